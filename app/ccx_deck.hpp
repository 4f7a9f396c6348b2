// `hexfem modal --ccx-deck JOB.inp`: the same modal analysis as a CalculiX deck, so a user can
// check hexfem's frequencies with an independent solver in one command (`ccx JOB`).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fem/modal_solver.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// CalculiX has no pyramid: an order-2 pyramid goes out as a C3D20 collapsed onto its apex
// (write_inp). How many of the mesh's pyramids that map turns inside out at C3D20's 3x3x3 Gauss
// points, where ccx checks it ("nonpositive jacobian": it refuses the whole deck), although
// hexfem's own pyramid13 is valid there. 0 at order 1 (C3D8 with the apex repeated).
long pyramids_ccx_refuses(const MixedMesh& mesh);
// The same per cell, for write_inp's reduced_pyramids (they go out as C3D20R): 1 for such a
// pyramid valid at C3D20R's 2x2x2 points, 2 for one inside out there too; empty when none.
std::vector<char> pyramids_ccx_refuses_mask(const MixedMesh& mesh);
// The warning for an .inp written with that mask ("" when it flags nothing).
std::string ccx_pyramid_warning(const std::vector<char>& mask, const std::filesystem::path& inp);

// For the deck: the pyramids `mask` flags 2 (inside out at C3D20R's points too) made straight,
// each mid-edge node at its edge's middle (the cells sharing those edges follow). Returns how
// many.
long straighten_for_ccx(MixedMesh& mesh, const std::vector<char>& mask);

// JOB_mesh.inp beside JOB.inp.
std::filesystem::path ccx_deck_mesh_path(const std::filesystem::path& deck);

struct CcxDeckFiles {
  std::filesystem::path deck, mesh;
  std::string warning;  // ccx_pyramid_warning of the mesh file, "" when none
};
// Writes JOB_mesh.inp (write_inp: nodes, elements, sets, the NC faces' ties as *EQUATION, hexes
// as C3D8I when the solve used incompatible modes, pyramids ccx would refuse as C3D20R) and
// JOB.inp, which includes it and adds one *MATERIAL and *SOLID SECTION per solid
// (options.material), a *BOUNDARY line per fixed node (`fixed`: 3 per node, as
// select_fixed_dofs) and a *FREQUENCY step for options.num_modes. Units: the mesh's lengths,
// newtons and seconds (mm, N, t for a mesh in mm: E in MPa), so ccx prints Hz. The formulations
// that differ from hexfem's (CalculiX has no pyramid, integrates wedges and linear tets with
// fewer points): validation/crosscheck.md. Each file is written to a temporary name and renamed.
CcxDeckFiles write_ccx_deck(const MixedMesh& mesh, const ModalOptions& options,
                            const std::vector<std::uint8_t>& fixed,
                            const std::filesystem::path& deck);

}  // namespace hexfem
