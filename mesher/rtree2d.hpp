// Boost.Geometry R-tree types for searches in a face's parameter plane.
#pragma once

#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <utility>

namespace hexfem::rt2 {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using Point = bg::model::point<double, 2, bg::cs::cartesian>;
using Box = bg::model::box<Point>;
using BoxTree = bgi::rtree<std::pair<Box, int>, bgi::quadratic<16>>;
using PointTree = bgi::rtree<std::pair<Point, int>, bgi::rstar<16>>;

}  // namespace hexfem::rt2
