// The conformal pass's last step: a boundary quad's bilinear face bulges off the two surface
// triangles the tets had under it, by up to half the flat tet on its four corners. Interior
// bulges cancel between the two cells of a face, the boundary ones add up: on coarse curved
// parts (Cone_1 at diagonal/30: 1.13e-3) they take the enclosed volume past the tet mesh's by
// more than the volume-gap budget. Those that bulge most are given back two triangles, along the
// diagonal that moves the volume towards the tets'; conformal.cpp then splits their cells.
//
// Takes: a watertight order-1 mixed mesh, the tet mesh's volume and the budget.
// Gives: the boundary quads (bface) turned into two triangles (BulgeSplit), until the volume
//        enclosed by the boundary is predicted within 0.8 x budget of the target.
// Keeps: every other boundary face, the cells (conformal.cpp changes them).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct BulgeSplit {
  std::array<std::int32_t, 4> quad;      // as stored
  std::int32_t first = -1, second = -1;  // the two boundary triangles' bface indices
};

// The volume enclosed by the boundary faces (divergence theorem; a bilinear quad as the mean of
// its two triangulations, which is exact).
double enclosed_volume(const MixedMesh& mesh);

// Turns the most-bulging boundary quads into triangle pairs (see above); returns them.
std::vector<BulgeSplit> triangulate_bulging_boundary_quads(MixedMesh& mesh, double target_volume,
                                                           double budget);

// Gives back the quad of each split whose two triangles are not both faces of a cell (the cell
// could not be split without a flat cell); returns how many.
std::size_t restore_unsplit_boundary_quads(MixedMesh& mesh, const std::vector<BulgeSplit>& splits);

}  // namespace hexfem
