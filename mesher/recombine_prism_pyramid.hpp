// After the hexes: prisms from three free tets (enumerated from their lowest vertex like the
// hexes, same quality threshold, conformity rules and CAD-face rule), then pyramids from two free
// tets resting on a quad face of a hex or prism that no other element shares (paper,
// "Yamakawa-Shimada's algorithm and finite element conformity").
//
// Takes: the RecombineState after the hexes.
// Gives: prisms, pyramids and pyramids around slivers, placed into the state.
// Keeps: the state's invariant (each tet in one place) at the end of each function.
#pragma once

#include <vector>

#include "mesher/recombine_place.hpp"
#include "mesher/recombine_slivers.hpp"
#include "mesher/recombine_state.hpp"

namespace hexfem {

// Candidate prisms around free tets (min quality s.limits.min_quality), sorted best first
// (filled by place_greedily, like hexes).
std::vector<Candidate> enumerate_prisms(const RecombineState& s);

// Candidate pyramids on the unshared interior quad faces of s.elements (hexes and prisms), made
// of two free tets with a common apex and a min scaled Jacobian of at least
// s.limits.min_pyramid_quality (a pyramid whose apex lies in the plane of two base edges is flat
// at that corner).
std::vector<Candidate> enumerate_pyramids(const RecombineState& s);

// Places pyramids best first while both tets are free; returns how many.
std::size_t place_pyramids(RecombineState& s, std::vector<Candidate>& cands);

// A free tet with min scaled Jacobian below s.limits.sliver_quality that lies on no element's
// quad face (the sliver between two diagonal splits of a near-planar quad (a, b, c, d) among
// tets) is merged with the two free tets across one diagonal's triangles when they share their
// fourth vertex: a pyramid with that apex over the quad, if its min scaled Jacobian reaches
// s.limits.min_pyramid_quality and its base shares no three corners with a different quad face
// of an element (or of a pyramid made before: that face would be neither matched nor split
// into triangles). Best pyramid first, flattest sliver first; returns how many were placed.
std::size_t merge_slivers_into_pyramids(RecombineState& s);

// Pyramids holding a tet that shares a face with a free tet below s.limits.sliver_quality, and
// any element with a tet on an edge of one below s.limits.keep_tet_quality (a flat tet: its
// edges' shells are what the flips need), go back to tets (their tets freed, the elements
// erased), so that merge_slivers_into_pyramids and the flips can use them. Returns how many went.
// Slivers absorbed into them must then be checked again (release_orphan_slivers).
std::size_t dissolve_pyramids_next_to_slivers(RecombineState& s);

}  // namespace hexfem
