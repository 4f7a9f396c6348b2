// Recombination of tets into hexahedra (paper, "Yamakawa-Shimada's algorithm"; enumeration as
// Pellerin, Johnen & Remacle 2017, "a vertex based strategy"): every hex whose 12 edges are tet
// edges and whose 8 vertices span tets that fill it exactly, whatever the number (5, 6, 7) or
// pattern of those tets, is found from its lowest vertex; candidates below a quality threshold
// are dropped; the rest are placed best first when all their tets are free and the conformity
// rules hold.
//
// Takes: the TetTopology.
// Gives: candidate hexes, best first (place_greedily places them into the RecombineState).
// Keeps: candidates only; each is found once, from its lowest vertex.
#pragma once

#include <limits>
#include <vector>

#include "mesher/recombine_place.hpp"
#include "mesher/recombine_slivers.hpp"

namespace hexfem {

struct HexOptions {
  double min_quality = 0.3;  // hexes with a lower min scaled Jacobian are not candidates
  FillRules fill;
  // place_hexes_greedily's bands of quality, decreasing lower ends (the last band reaches down
  // to min_quality). Any bands give the same hexes; these measured fastest on ANC101 at 1M
  // vertices.
  std::vector<float> quality_bands = {0.8f, 0.6f};
};

// Candidates of quality q with from <= q < below.
struct QualityBand {
  float from = -std::numeric_limits<float>::infinity();
  float below = std::numeric_limits<float>::infinity();
};

// Every candidate hex in the band (in sorted runs: best first once merged, deterministic): eight
// vertices whose twelve edges and six quad faces are made of mesh edges and triangles (with
// `used`: triangles of free tets), with every corner's scaled Jacobian at least min_quality.
// Whether tets fill it is checked when it is placed (place_greedily).
SortedRuns<HexCorners> enumerate_hexes(const TetTopology& topo, const HexOptions& options,
                                       const QualityBand& band = {},
                                       const std::vector<char>* used = nullptr);

// The hexes of enumerate_hexes (without `used`) that tets fill whether free or not, with their
// tets, fill-tested where each is found. *found: how many the enumeration found.
SortedRuns<Candidate> enumerate_filled_hexes(const TetTopology& topo, const HexOptions& options,
                                             const QualityBand& band = {},
                                             std::size_t* found = nullptr);

// Every candidate hex as one list, best first (for studies of the selection: the pipeline places
// them band by band instead).
std::vector<Candidate> hex_candidate_list(const TetTopology& topo, const HexOptions& options);

// The candidates of hex_candidate_list that tets fill whether free or not (fills_element without
// `used`), with their tets, best first. The fill test runs where each hex is found, while its
// vertices' tets are in cache: at a million vertices twice as fast as on the sorted list.
std::vector<Candidate> fillable_hex_list(const TetTopology& topo, const HexOptions& options,
                                         const QualityBand& band = {});

// The hexes of `found` (each listed once) that tets fill, with their tets, best first,
// keeping only those with a free tet (used[t] == 0) whose four vertices are corners of the hex,
// not all on one face (a sliver flat on a face is not inside).
std::vector<Candidate> hexes_holding_free_tets(const TetTopology& topo, const HexOptions& options,
                                               const SortedRuns<HexCorners>& found,
                                               const std::vector<char>& used);

// The same for the hexes in the band found around the tets search_mask leaves open
// (enumerate_hexes with used = search_mask), tested where each is found, while its tets are in
// cache. Each is found once.
std::vector<Candidate> hexes_holding_free_tets(const TetTopology& topo, const HexOptions& options,
                                               const QualityBand& band,
                                               const std::vector<char>& search_mask,
                                               const std::vector<char>& used);

// The paper's greedy placement of every candidate hex, best first, into s (place_greedily),
// band by band; adds the number of candidates enumerated to *candidates. Returns the hexes
// placed.
// With `kept`: every band's candidates at or above kept_from, copied there (for the swaps).
std::size_t place_hexes_greedily(RecombineState& s, const HexOptions& options,
                                 ConformityIndex& index, std::size_t* candidates = nullptr,
                                 SortedRuns<HexCorners>* kept = nullptr, float kept_from = 0);

}  // namespace hexfem
