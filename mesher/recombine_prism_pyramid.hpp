// After the hexes: prisms from three free tets (enumerated from their lowest vertex like the
// hexes, same quality threshold, conformity rules and CAD-face rule), then pyramids from two free
// tets resting on a quad face of a hex or prism that no other element shares (paper,
// "Yamakawa-Shimada's algorithm and finite element conformity").
#pragma once

#include <vector>

#include "mesher/recombine_place.hpp"
#include "mesher/recombine_slivers.hpp"

namespace hexfem {

struct PrismOptions {
  double min_quality = 0.3;
  FillRules fill;
};

// Candidate prisms around free tets, sorted best first (filled by place_greedily, like hexes).
std::vector<Candidate> enumerate_prisms(const TetTopology& topo, const std::vector<char>& used,
                                        const PrismOptions& options);

// Candidate pyramids on the unshared interior quad faces of `elements` (hexes and prisms),
// made of two free tets with a common apex and a min scaled Jacobian of at least min_quality
// (a pyramid whose apex lies in the plane of two base edges is flat at that corner).
std::vector<Candidate> enumerate_pyramids(const TetTopology& topo,
                                          const std::vector<Candidate>& elements,
                                          const std::vector<char>& used, double min_quality);

// Keeps pyramids best first while both tets are free; marks them used.
std::vector<Candidate> place_pyramids(std::vector<Candidate>& cands, std::vector<char>& used);

// A free tet with min scaled Jacobian below flat_sj that lies on no element's quad face (the
// sliver between two diagonal splits of a near-planar quad (a, b, c, d) among tets) is merged
// with the two free tets across one diagonal's triangles when they share their fourth vertex:
// a pyramid with that apex over the quad, if its min scaled Jacobian reaches min_pyramid and
// its base shares no three corners with a different quad face of `elements` (or of a pyramid
// made before: that face would be neither matched nor split into triangles).
// Best pyramid first, flattest sliver first; marks the tets used and returns the pyramids.
// Pyramids holding a tet that shares a face with a free tet of min scaled Jacobian below
// flat_sj, and any element with a tet on an edge of one below element_sj (a flat tet: its
// edges' shells are what the flips need), go back to tets (their tets freed, the elements
// erased from `elements`), so that merge_slivers_into_pyramids and the flips can use them. Returns
// how many went. Slivers absorbed into them must then be checked again (release_orphan_slivers).
std::size_t dissolve_pyramids_next_to_slivers(const TetTopology& topo,
                                              std::vector<Candidate>& elements,
                                              std::vector<char>& used, double flat_sj,
                                              double element_sj);

std::vector<Candidate> merge_slivers_into_pyramids(const TetTopology& topo,
                                                   const std::vector<Candidate>& elements,
                                                   std::vector<char>& used, double flat_sj,
                                                   double min_pyramid);

}  // namespace hexfem
