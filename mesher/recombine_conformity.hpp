// After the pyramids: hexes and prisms that stick out of the hex-dominant region make more
// non-conformal (NC) quad faces than they remove. An element with a quad faces facing tets (NC)
// and b quad faces matched by another hex or prism turns, when undone into its tets, its a NC
// faces into plain tet faces and its b partners' faces into NC ones: the NC count drops by
// a - b. Undoing the elements with a - b > 0, then making pyramids on the partners' new free
// quad faces (which matches them again), lowers the NC share at a small cost in hexes; the paper
// counts NC faces as the price of its recombination (section "Yamakawa-Shimada's algorithm and
// finite element conformity").
#pragma once

#include <cstdint>
#include <vector>

#include "mesher/recombine_common.hpp"

namespace hexfem {

struct NcRepair {
  std::size_t nc_before = 0, nc_after = 0;  // NC quad faces of the elements, before and after
  std::size_t undone[kNumCellKinds] = {};   // elements turned back into tets, by kind
  std::size_t pyramids_added = 0;           // pyramids made afterwards on freed quad faces
};

// Quad faces of the elements that face tets (NC): not shared with another element and not on
// the surface.
std::size_t count_nc_faces(const TetTopology& topo, const std::vector<Candidate>& elements);

// Undoes the elements whose undoing lowers the NC count by at least 1 (a hex: by at least
// min_hex_gain; a hex is worth more than one NC face), largest gain first, never two neighbours
// in one round; pyramids resting on an undone element go too. Then (if make_pyramids) makes
// pyramids of at least min_pyramid quality on the unshared quad faces left. An element is only
// undone when every tet it gives back has a min scaled Jacobian of at least keep_sj. Absorbed
// slivers that no longer qualify are freed (release_orphan_slivers with flat_sj).
NcRepair undo_nonconformal_elements(const TetTopology& topo, std::vector<Candidate>& elements,
                                    std::vector<std::int32_t>& absorbed, std::vector<char>& used,
                                    double flat_sj, double keep_sj, double min_pyramid,
                                    int min_hex_gain = 2, bool make_pyramids = true);

}  // namespace hexfem
