// Checks of a surface mesh: closed 2-manifold per solid (lumps of a solid may touch along a CAD
// edge), consistent outward orientation,
// self-intersection (CGAL Polygon Mesh Processing), triangle angles, enclosed volume, and the
// alignment measure (share of right-isosceles-like triangles).
//
// Takes: a SurfaceMesh.
// Gives: a SolidCheck per solid.
// Keeps: read-only.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/surface_mesh.hpp"

namespace hexfem {

// Right-isosceles-like: the largest angle within 10° of 90°, the other two within 10° of 45°.
bool is_right_isosceles(const Vec3& a, const Vec3& b, const Vec3& c);
// The three angles of a triangle, in degrees.
std::array<double, 3> triangle_angles(const Vec3& a, const Vec3& b, const Vec3& c);

// A corner of a CAD face at a mesh node: the face's interior angle there, measured on the CAD
// model (edge_points.hpp, face_corners).
struct CadCorner {
  int node = 0;
  int face = 0;
  int vertex = 0;    // CAD vertex id
  double angle = 0;  // degrees
};
// The corners of every face of `cad` whose vertex is a node of `m` (at exactly its point).
std::vector<CadCorner> cad_corners(const CadModel& cad, const MixedMesh& m);

struct TriangleQuality {
  std::size_t triangles = 0;
  double min_angle = 180, max_angle = 0;  // degrees
  std::size_t below_5 = 0;                // triangles with an angle below 5°
  // Of those, the ones forced by the CAD model: their smallest angle is at a corner of their
  // CAD face whose own angle is below 5° (the angles there of the face's triangles add up to
  // the corner's, so one of them at least is that small).
  std::size_t below_5_at_cad_corners = 0;
  // The CAD corner angles behind those (degrees; 0 when there are none).
  double forcing_corner_min = 0, forcing_corner_max = 0;
  double right_isosceles_share = 0;
};
// `corners`: the CAD corners at the mesh's nodes (cad_corners); without them no small angle
// counts as forced.
TriangleQuality triangle_quality(const MixedMesh& mesh, const std::vector<CadCorner>& corners = {});

struct SolidCheck {
  int solid = 0;
  std::size_t triangles = 0;
  std::size_t open_edges = 0;         // used by one triangle
  std::size_t nonmanifold_edges = 0;  // used by more than two, not as touching sheets
  // Used twice each way on a CAD edge: two lumps of the solid touching along it (allowed).
  std::size_t touching_edges = 0;
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
