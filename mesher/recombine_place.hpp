// Candidates found on all threads in a thread-independent order, and the paper's greedy
// best-first placement of them under the fill test and the conformity rules.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "mesher/recombine_fill.hpp"
#include "mesher/recombine_rules.hpp"
#include "mesher/recombine_state.hpp"

namespace hexfem {

// Candidates as found on the threads: one sorted run per thread. The runs together are the
// candidates best first once merged (they are distinct and totally ordered, so the merged order
// does not depend on which thread found what).
template <class T>
struct SortedRuns {
  std::vector<std::vector<T>> runs;
  std::size_t size() const {
    std::size_t n = 0;
    for (const auto& r : runs) n += r.size();
    return n;
  }
};

// Runs find(v, scratch, out) for every vertex on all threads; each thread's finds are sorted.
// (Defined for Candidate and HexCorners.)
template <class T>
using FindInto = std::function<void(std::int32_t v, FillScratch& scratch, std::vector<T>& out)>;
template <class T>
SortedRuns<T> find_sorted_runs(std::int32_t num_vertices, const FindInto<T>& find);

// The next (at most) `count` candidates of the merged runs, from the positions `at` (one per
// run, advanced), appended to `out`.
template <class T, class Emit>
void merge_runs_step(const SortedRuns<T>& r, std::vector<std::size_t>& at, std::size_t count,
                     const Emit& emit) {
  const std::size_t k = r.runs.size();
  for (std::size_t n = 0; n < count; ++n) {
    std::size_t best = k;
    for (std::size_t i = 0; i < k; ++i)
      if (at[i] < r.runs[i].size() && (best == k || r.runs[i][at[i]] < r.runs[best][at[best]]))
        best = i;
    if (best == k) return;
    emit(r.runs[best][at[best]++]);
  }
}

// Runs find(v, scratch, out) for every vertex on all threads and returns the candidates
// sorted best first (the sort makes the result independent of the thread schedule).
using FindCandidates = FindInto<Candidate>;
std::vector<Candidate> collect_candidates(std::int32_t num_vertices, const FindCandidates& find);

// Greedy best-first placement: keeps each candidate, in the order given, that tets fill
// (fills_element, for candidates whose tets are not known yet), whose tets are all free and
// that breaks no conformity rule (s.limits.fill). Appends the kept candidates to s.elements in
// order, their tets marked used; returns how many. `next(chunk)` gives the candidates a chunk at
// a time (an empty chunk ends them). The fill test of a chunk's candidates runs first, on all
// threads: only its last check (the tets are free) depends on the placement, and the serial
// pass makes that check itself.
using CandidateChunks = std::function<void(std::vector<Candidate>& chunk)>;
std::size_t place_greedily(RecombineState& s, const CandidateChunks& next, ConformityIndex& index);
// The same on a list (sorted first unless it is).
std::size_t place_greedily(RecombineState& s, std::vector<Candidate>& cands,
                           ConformityIndex& index);
// The same on the hex enumeration's runs, merged on the way.
std::size_t place_greedily(RecombineState& s, const SortedRuns<HexCorners>& cands,
                           ConformityIndex& index);

}  // namespace hexfem
