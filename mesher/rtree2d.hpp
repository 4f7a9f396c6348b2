// Boost.Geometry R-tree types for searches in a face's parameter plane.
#pragma once

#include <algorithm>
#include <array>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cstddef>
#include <utility>
#include <vector>

namespace hexfem::rt2 {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using Point = bg::model::point<double, 2, bg::cs::cartesian>;
using Box = bg::model::box<Point>;
using BoxTree = bgi::rtree<std::pair<Box, int>, bgi::quadratic<16>>;
using PointTree = bgi::rtree<std::pair<Point, int>, bgi::rstar<16>>;

// The bounding box of each segment (a pair of indices into uv), tagged with its index.
inline std::vector<std::pair<Box, int>> segment_boxes(
    const std::vector<std::array<double, 2>>& uv, const std::vector<std::array<int, 2>>& segments) {
  std::vector<std::pair<Box, int>> boxes;
  boxes.reserve(segments.size());
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const auto& a = uv[static_cast<std::size_t>(segments[s][0])];
    const auto& c = uv[static_cast<std::size_t>(segments[s][1])];
    boxes.emplace_back(Box(Point(std::min(a[0], c[0]), std::min(a[1], c[1])),
                           Point(std::max(a[0], c[0]), std::max(a[1], c[1]))),
                       static_cast<int>(s));
  }
  return boxes;
}

}  // namespace hexfem::rt2
