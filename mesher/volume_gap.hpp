// The mixed mesh against the tet mesh it was made from: an element's faces are bilinear, so a
// twisted quad face that no other element shares (a boundary quad, or an NC quad facing tets)
// opens a gap against the tets across it. The gap of the whole mesh is the sum over elements of
// V(element) - V(its tets), minus the absorbed slivers: each term depends on its element alone,
// so undoing an element into its tets changes the total by exactly its own term. This stage
// undoes the elements that lose the most volume per unit of their own volume until the total is
// within a budget.
//
// Takes: the RecombineState after the NC repair and the gap budget.
// Gives: elements undone until |V(mixed) - V(tets)| <= budget (VolumeGap).
// Keeps: the state's invariant; no element undone into a tet flatter than keep_tet_quality.
#pragma once

#include <cstdint>
#include <vector>

#include "mesher/recombine_slivers.hpp"
#include "mesher/recombine_state.hpp"

namespace hexfem {

struct VolumeGap {
  double tets = 0;        // V(all tets)
  double gap_before = 0;  // V(mixed) - V(tets), before and after
  double gap_after = 0;
  std::size_t undone[kNumCellKinds] = {};  // elements turned back into tets, by kind
};

// V(element) - V(its tets).
double element_gap(const TetTopology& topo, const Candidate& e);

// V(mixed) - V(tets) of elements + free tets + absorbed slivers (see above).
double volume_gap(const TetTopology& topo, const std::vector<Candidate>& elements,
                  const std::vector<std::int32_t>& absorbed);

// Undoes elements (worst loss per volume first) until |gap| <= max_rel_gap * V(tets). An
// element is only undone when every tet it gives back, absorbed slivers included, has a min
// scaled Jacobian of at least s.limits.keep_tet_quality (so no flat cell appears). Absorbed
// slivers that no longer qualify are freed (release_orphan_slivers).
VolumeGap limit_volume_gap(RecombineState& s, double max_rel_gap);

}  // namespace hexfem
