// Tetrahedralization of the surface triangles plus the interior points with TetGen (libtet):
// every surface triangle is kept as it is (no Steiner point on the boundary, "-Y"), no quality
// refinement (no "-q"), and each tet is assigned to the solid that contains it. The Delaunay
// tetrahedralization of the points is constrained to the surface by flips; TetGen's pass that
// makes the faces next to the boundary Delaunay again afterwards is left out unless asked.
//
// Takes: the SurfaceMesh and the interior points.
// Gives: a TetMesh: positive tets, each with its solid.
// Keeps: every surface triangle is a tet face; surface nodes first, then interior points.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesher/solid_locator.hpp"
#include "mesher/surface_mesh.hpp"

namespace hexfem {

struct TetMesh {
  // Surface nodes first (same indices as the SurfaceMesh), then the interior points in the order
  // given, then any Steiner point TetGen had to add inside the volume to recover the boundary.
  std::vector<Vec3> nodes;
  std::vector<std::array<std::int32_t, 4>> tets;  // positively oriented (Gmsh Tet4)
  std::vector<std::int32_t> tet_solid;
  std::size_t steiner_points = 0;
  std::size_t dropped_tets = 0;  // TetGen tets outside every solid (inner voids), removed
  // TetGen's own run (its steps in the child process, wall clock): the "tetgen" stage also
  // holds the input's conversion, the output's transfer and checks, and the region fill.
  double tetgen_seconds = 0;
};

// Throws hexfem::Error when TetGen fails (naming the intersecting surface triangles and their
// CAD faces when the surface self-intersects) or when its boundary differs from the input.
// recover_delaunay: TetGen's Delaunay recovery after the boundary recovery (what "tetgen -pY"
// does; off by default: it is most of TetGen's time at scale and changes only tets next to the
// boundary; --tetgen-delaunay-recovery measures it).
TetMesh tetrahedralize(const SurfaceMesh& surface, const std::vector<Vec3>& interior_points,
                       const SolidLocator& locator, bool recover_delaunay = false);

}  // namespace hexfem
