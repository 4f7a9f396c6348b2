// Candidates found on all threads in a thread-independent order, and the paper's greedy
// best-first placement of them under the fill test and the conformity rules.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "mesher/recombine_fill.hpp"
#include "mesher/recombine_rules.hpp"
#include "mesher/recombine_state.hpp"

namespace hexfem {

// Runs find(v, scratch, out) for every vertex on all threads and returns the candidates
// sorted best first (the sort makes the result independent of the thread schedule).
using FindCandidates =
    std::function<void(std::int32_t v, FillScratch& scratch, std::vector<Candidate>& out)>;
std::vector<Candidate> collect_candidates(std::int32_t num_vertices, const FindCandidates& find);

// Greedy best-first placement: sorts `cands` (unless sorted) and keeps each one that tets fill
// (fills_element, for candidates whose tets are not known yet), whose tets are all free and
// that breaks no conformity rule (s.limits.fill). Appends the kept candidates to s.elements in
// order, their tets marked used; returns how many. The fill test of every candidate runs first,
// on all threads: only its last check (the tets are free) depends on the placement, and the
// serial pass makes that check itself.
std::size_t place_greedily(RecombineState& s, std::vector<Candidate>& cands,
                           ConformityIndex& index);

}  // namespace hexfem
