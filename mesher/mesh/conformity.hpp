// Non-conformal quad faces: an interior quad face of a cell that is not matched by an identical
// quad face of another cell but touches triangle faces (two tets, a pyramid's side, ...).
#pragma once

#include <vector>

#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Recomputes mesh.nc_cell / mesh.nc_local_face from the cells.
void flag_nonconformal_quads(MixedMesh& mesh);
// The same from sorted_cell_faces(mesh), for a caller that needs those faces again.
void flag_nonconformal_quads(MixedMesh& mesh, const std::vector<CellFaceRef>& faces);

struct QuadFaceCounts {
  std::size_t interior = 0;      // quad faces shared with another cell (matched or NC)
  std::size_t nonconformal = 0;  // of those, the ones touching triangles
};
QuadFaceCounts count_quad_faces(const MixedMesh& mesh);
QuadFaceCounts count_quad_faces(const std::vector<CellFaceRef>& faces);  // sorted_cell_faces

}  // namespace hexfem
