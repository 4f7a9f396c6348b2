// Closest points on the part's geometry, for the nodes of curved (order-2) elements.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "mesher/cad/cad_model.hpp"

namespace hexfem {

// The point of the geometry nearest p where a mesh edge between CAD faces f1 and f2 lies: on
// face f1's surface when f1 == f2, else on the CAD edge the two faces share (the nearest one if
// they share several). Empty when the projection fails or the faces share no edge.
std::optional<Vec3> closest_point_on_geometry(const CadModel& cad, const Vec3& p, int f1, int f2);

// closest_point_on_geometry for many points, with the same results: each face's and edge's
// projector is set up once (OCCT samples a B-spline surface on a grid for each new projector,
// most of the time of a projection) and the edges two faces share are listed once. Not to be
// shared between threads: one per thread.
class GeometryProjector {
 public:
  explicit GeometryProjector(const CadModel& cad);
  ~GeometryProjector();
  GeometryProjector(GeometryProjector&&) noexcept;
  std::optional<Vec3> closest(const Vec3& p, int f1, int f2);

 private:
  struct Cache;
  const CadModel* cad_;
  std::unique_ptr<Cache> cache_;
};

}  // namespace hexfem
