// Checks of a surface mesh: closed 2-manifold per solid, consistent outward orientation,
// self-intersection (CGAL Polygon Mesh Processing), triangle angles, enclosed volume, and the
// alignment measure (share of right-isosceles-like triangles).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "mesher/surface_mesh.hpp"

namespace hexfem {

// Right-isosceles-like: the largest angle within 10° of 90°, the other two within 10° of 45°.
bool is_right_isosceles(const Vec3& a, const Vec3& b, const Vec3& c);
// The three angles of a triangle, in degrees.
std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c);

struct TriangleQuality {
  std::size_t triangles = 0;
  double min_angle = 180, max_angle = 0;  // degrees
  std::size_t below_5 = 0;                // triangles with an angle below 5°
  // Of those, the ones whose smallest angle sits between two edges on CAD edges (a corner of
  // a face sharper than 5° in the CAD model, which no triangulation of the face can avoid).
  std::size_t below_5_at_sharp_corners = 0;
  // Of the others, those whose three corners all lie on CAD edges with the short side a chord
  // across the face (not on a CAD edge): the face is narrower there than any spacing of its
  // edge points can follow (next to a tangent cusp, where two CAD edges meet at 0°).
  std::size_t below_5_across_gaps = 0;
  double right_isosceles_share = 0;
};
TriangleQuality triangle_quality(const MixedMesh& mesh);

struct SolidCheck {
  int solid = 0;
  std::size_t triangles = 0;
  std::size_t open_edges = 0;         // used by one triangle
  std::size_t nonmanifold_edges = 0;  // used by more than two
  std::size_t misoriented_edges = 0;  // two triangles running the same way along it
  bool self_intersects = false;       // only tested on a closed, oriented manifold
  bool self_intersection_tested = false;
  double volume = 0;  // enclosed by the triangles (divergence theorem), > 0 when outward
  bool ok() const {
    return open_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0 &&
           !self_intersects && volume > 0;
  }
};
std::vector<SolidCheck> check_solids(const SurfaceMesh& surface, bool self_intersection = true);

// One line per defect, naming the CAD faces involved (for study programs and error reports):
// edges used once or more than twice, misoriented edges, self-intersecting triangle pairs,
// triangles with an angle below 5 degrees. At most max_lines lines per kind.
std::vector<std::string> surface_defects(const SurfaceMesh& surface, std::size_t max_lines = 10);

}  // namespace hexfem
