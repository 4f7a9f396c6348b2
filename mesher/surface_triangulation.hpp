// Stage 5: triangulation of each face from its points, in the parameter plane (CGAL
// constrained Delaunay, the edge points' segments as constraints), scaled by the face's mean
// metric, then edge flips toward the Delaunay criterion measured on the 3D triangles, so the
// lattice of the packing comes out as right triangles in 3D.
//
// Takes: a face's boundary and interior points.
// Gives: its triangles over local point ids (FaceTriangles).
// Keeps: every boundary segment an edge of the triangulation (the faces stay conforming).
#pragma once

#include <array>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/edge_points.hpp"
#include "mesher/surface_points.hpp"

namespace hexfem {

struct FaceTriangles {
  // Local ids: i < boundary.uv.size() is boundary point i (node boundary.node[i]); otherwise
  // interior point i - boundary.uv.size(). Counter-clockwise in the parameter plane. Triangles
  // that collapse on a singular point (two corners on one node) are left out.
  std::vector<std::array<int, 3>> triangles;
  std::vector<bool> interior_used;  // per interior point: in some triangle
  std::size_t flips = 0;
};

// Throws hexfem::Error when the boundary cannot be recovered as triangle edges. With the CAD
// model, an interior point of a triangle that faces against the surface (a fold: the point lies
// beyond the face's edge in space although inside its trimmed domain) is left out.
FaceTriangles triangulate_face(int f, const FaceBoundary& boundary, const FacePoints& interior,
                               const EdgePoints& points, Vec2 scale, const CadModel* cad = nullptr);

}  // namespace hexfem
