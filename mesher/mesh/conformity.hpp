// Non-conformal quad faces: an interior quad face of a cell that is not matched by an identical
// quad face of another cell but touches triangle faces (two tets, a pyramid's side, ...).
#pragma once

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Recomputes mesh.nc_cell / mesh.nc_local_face from the cells.
void flag_nonconformal_quads(MixedMesh& mesh);

struct QuadFaceCounts {
  std::size_t interior = 0;      // quad faces shared with another cell (matched or NC)
  std::size_t nonconformal = 0;  // of those, the ones touching triangles
};
QuadFaceCounts count_quad_faces(const MixedMesh& mesh);

}  // namespace hexfem
