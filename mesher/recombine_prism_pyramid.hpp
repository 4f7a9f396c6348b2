// After the hexes: prisms from three free tets (enumerated from their lowest vertex like the
// hexes, same quality threshold, conformity rules and CAD-face rule), then pyramids from two free
// tets resting on a quad face of a hex or prism that no other element shares (paper,
// "Yamakawa-Shimada's algorithm and finite element conformity").
#pragma once

#include <vector>

#include "mesher/recombine_common.hpp"

namespace hexfem {

struct PrismOptions {
  double min_quality = 0.3;
  FillRules fill;
};

// Candidate prisms around free tets, sorted best first (filled by place_greedily, like hexes).
std::vector<Candidate> enumerate_prisms(const TetTopology& topo, const std::vector<char>& used,
                                        const PrismOptions& options);

// Candidate pyramids on the unshared interior quad faces of `elements` (hexes and prisms),
// made of two free tets with a common apex and a positive Jacobian at every base corner.
std::vector<Candidate> enumerate_pyramids(const TetTopology& topo,
                                          const std::vector<Candidate>& elements,
                                          const std::vector<char>& used);

// Keeps pyramids best first while both tets are free; marks them used.
std::vector<Candidate> place_pyramids(std::vector<Candidate>& cands, std::vector<char>& used);

}  // namespace hexfem
