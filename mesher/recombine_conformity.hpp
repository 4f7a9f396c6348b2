// After the pyramids: hexes and prisms that stick out of the hex-dominant region make more
// non-conformal (NC) quad faces than they remove. An element with a quad faces facing tets (NC)
// and b quad faces matched by another hex or prism turns, when undone into its tets, its a NC
// faces into plain tet faces and its b partners' faces into NC ones, except those on which two
// of its own tets with a common apex make a pyramid (made at once): the NC count drops by
// a - b + those pyramids. Then prisms fill wedge-shaped gaps where two elements' NC (or
// pyramid-covered) faces meet at an edge, and pyramids are made on the faces left. This lowers
// the NC share at a small cost in hexes; the paper counts NC faces as the price of its
// recombination (section "Yamakawa-Shimada's algorithm and finite element conformity").
//
// Takes: the RecombineState after the pyramids.
// Gives: fewer NC faces: elements undone, pyramids and prisms made (NcRepair).
// Keeps: the state's invariant; no element undone into a tet flatter than keep_tet_quality.
#pragma once

#include <cstdint>
#include <vector>

#include "mesher/recombine_prism_pyramid.hpp"

namespace hexfem {

struct NcRepair {
  std::size_t nc_before = 0, nc_after = 0;  // NC quad faces of the elements, before and after
  std::size_t undone[kNumCellKinds] = {};   // elements turned back into tets, by kind
  std::size_t pyramids_added = 0;           // pyramids made afterwards on freed quad faces
  std::size_t prisms_added = 0;             // prisms made in gaps between elements
};

// Quad faces of the elements that face tets (NC): not shared with another element and not on
// the surface.
std::size_t count_nc_faces(const TetTopology& topo, const std::vector<Candidate>& elements);

struct NcRepairOptions {
  int min_hex_gain = 2;       // a hex is worth more than one NC face
  bool make_pyramids = true;  // pyramids behind undone elements and on the faces left
  bool make_prisms = true;    // prisms in gaps (only with make_pyramids)
};

// Undoes the elements whose undoing lowers the NC count by at least 1 (a hex: by at least
// o.min_hex_gain), largest gain first, never two neighbours in one round; pyramids resting on an
// undone element go too, and (if make_pyramids) its tets make pyramids of at least
// s.limits.min_pyramid_quality on its partners' faces where they can. With make_prisms (and
// make_pyramids): prisms under the prism stage's rules whose quad faces match two faces of
// elements, made of free tets and of whole pyramids' tets, where that lowers the NC count (a
// face it leaves facing tets counts against it unless a pyramid can go there). Then (if
// make_pyramids) pyramids on the unshared quad faces left. An element is only undone when every
// tet it gives back reaches s.limits.keep_tet_quality. Absorbed slivers that no longer qualify
// are freed (release_orphan_slivers); slivers on a new prism's faces are absorbed
// (absorb_face_slivers).
NcRepair undo_nonconformal_elements(RecombineState& s, const NcRepairOptions& o = {});

}  // namespace hexfem
