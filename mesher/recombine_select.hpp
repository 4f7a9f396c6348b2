// A look-ahead selection of hexes after the paper's greedy best-first placement (issue 16):
// local search on the conflict graph of the candidates. Greedy keeps the best hex even when it
// blocks two others that could both have been made; a 1-for-k swap takes such a hex out and puts
// in k >= 2 candidates that conflict with it alone and not with each other. Every element put in
// passes the same fill test (fills_element) and conformity rules (ConformityIndex, paper Figs
// 15-18) as in the greedy pass, against every element placed at that time.
//
// Takes: the RecombineState after place_greedily and a pool of candidates with their tets: in
// the pipeline those holding a tet the greedy pass left free (hexes_holding_free_tets), since
// each hex a swap puts in holds one.
// Gives: the state with the swaps done (more elements, each tet still in one place).
// Keeps: deterministic for any thread count (fill tests on all threads, swaps in one order).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "mesher/recombine_fill.hpp"
#include "mesher/recombine_hex.hpp"
#include "mesher/recombine_state.hpp"

namespace hexfem {

// How the hexes are chosen among the candidates: the paper's greedy pass alone, or followed by
// the swaps below, on the candidates the greedy pass found (kSwap) or on a wider search
// (kSwapWide, the default: also every candidate around the hexes that touch a free tet by a face;
// ANC101 h = 4.5 H_nbr 80.01 against 78.84 %, 1M vertices 46 s against 40 s; volume.md).
enum class HexSelection { kGreedy, kSwap, kSwapWide };
// "greedy" / "swap" / "swap-wide"; throws hexfem::Error for another name.
HexSelection parse_hex_selection(const std::string& name);

struct SwapOptions {
  // Passes; each after the first looks only around what the one before changed, and the last
  // finds none (ANC101 h = 4.5: 8 rounds; at 1M vertices the 30 are used).
  int max_rounds = 30;
  // Candidates below this min scaled Jacobian are not put in. 0.3, the hexes' own floor, since
  // the pool holds only candidates with a free tet (session 32): 0.5 gave ANC101 h = 4.5 H_nbr
  // 78.66 against 78.84 %, mean Q 0.976 against 0.975, and H_vol / 60 0.30 points less on
  // average over the shared models; at 1M vertices the swaps take 0.5 s more.
  double min_quality = 0.3;
  std::size_t max_partners = 24;      // best-first candidates tried per element taken out
  bool pair_swaps = true;             // also 2-for-k (k >= 3) swaps
  std::size_t max_pair_partners = 8;  // per pair: blocked by both, and by each alone
};

struct SwapReport {
  std::size_t fillable = 0;  // candidates that tets fill (placed or not)
  std::size_t rounds = 0, swaps = 0, removed = 0, inserted = 0;
};

// Whether elements a and b can both be placed: no tet in common and no conformity rule broken
// between them (the rules are symmetric).
bool compatible(const Candidate& a, const Candidate& b);

// The 1-for-k swaps (k >= 2) and the insertion of candidates that became free, in rounds until
// none is left or max_rounds. `pool`: candidates at or above options.min_quality that tets fill,
// with their tets, best first (all of them, placed or not: swap_pool; the pipeline's:
// hexes_holding_free_tets). Element order in s.elements: the kept ones as before, then the ones
// put in.
SwapReport improve_by_swaps(RecombineState& s, const std::vector<Candidate>& pool,
                            const SwapOptions& options = {});

// The tets a wider search for swap candidates may use (0) or not (1), after the greedy pass: the
// free tets and those of the elements that share a triangle with a free tet, leaving out the
// free tets whose component (free tets joined through shared triangles) holds only slivers flat
// on an element's quad face. A hex a 1-for-k swap puts in holds free tets and tets of the one
// element P taken out. A sliver of another element inside it would break the conformity rules
// against that element (or overlap its tets), and P's slivers alone would make it P: so it holds
// a free tet that is no sliver. Its tets are connected through shared triangles, so that tet's
// component touches P, and P is among these elements.
std::vector<char> wide_swap_search_mask(const RecombineState& s);

// Every candidate at or above options.min_quality that tets fill (fillable_hex_list): the
// widest pool, for studies and tests (at a million vertices eight million fill tests).
std::vector<Candidate> swap_pool(const TetTopology& topo, const HexOptions& hex,
                                 const SwapOptions& options = {});

}  // namespace hexfem
