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

// Merges SortedRuns best first: a heap of the runs' heads, the best on top.
template <class T>
class RunMerger {
 public:
  explicit RunMerger(const SortedRuns<T>& r) {
    for (const auto& run : r.runs)
      if (!run.empty()) heads_.push_back({run.data(), run.data() + run.size()});
    for (std::size_t i = heads_.size(); i-- > 0;) sift_down(i);
  }
  // The next candidate, best first; nullptr after the last.
  const T* next() {
    if (heads_.empty()) return nullptr;
    const T* c = heads_[0].cur++;
    if (heads_[0].cur == heads_[0].end) {
      heads_[0] = heads_.back();
      heads_.pop_back();
    }
    sift_down(0);
    return c;
  }

 private:
  struct Head {
    const T* cur;
    const T* end;
  };
  void sift_down(std::size_t i) {
    const std::size_t n = heads_.size();
    for (;;) {
      std::size_t best = i;
      for (std::size_t k = 2 * i + 1; k <= 2 * i + 2 && k < n; ++k)
        if (*heads_[k].cur < *heads_[best].cur) best = k;
      if (best == i) return;
      std::swap(heads_[i], heads_[best]);
      i = best;
    }
  }
  std::vector<Head> heads_;
};

// Runs find(v, scratch, out) for every vertex on all threads and returns the candidates
// sorted best first (the sort makes the result independent of the thread schedule).
using FindCandidates = FindInto<Candidate>;
std::vector<Candidate> collect_candidates(std::int32_t num_vertices, const FindCandidates& find);
// The runs merged into one list, best first.
std::vector<Candidate> merge_runs(const SortedRuns<Candidate>& runs);

// Greedy best-first placement: keeps each candidate, in the order given, that tets fill
// (fills_element, for candidates whose tets are not known yet), whose tets are all free and
// that breaks no conformity rule (s.limits.fill). Appends the kept candidates to s.elements in
// order, their tets marked used; returns how many. `next(chunk, free_around)` gives the
// candidates a chunk at a time (an empty chunk ends them); it may leave out those with a corner
// v of free_around[v] == 0 (no free tet around it: they cannot be placed any more). The fill test
// of a chunk's candidates runs first, on all threads: only its last check (the tets are free)
// depends on the placement, and the serial pass makes that check itself.
using CandidateChunks = std::function<void(std::vector<Candidate>& chunk,
                                           const std::vector<std::int32_t>& free_around)>;
std::size_t place_greedily(RecombineState& s, const CandidateChunks& next, ConformityIndex& index);
// The same on a list (sorted first unless it is).
std::size_t place_greedily(RecombineState& s, std::vector<Candidate>& cands,
                           ConformityIndex& index);
// The same on the hex enumeration's runs, merged on the way.
std::size_t place_greedily(RecombineState& s, const SortedRuns<HexCorners>& cands,
                           ConformityIndex& index);
// The same on runs of candidates whose tets are known.
std::size_t place_greedily(RecombineState& s, const SortedRuns<Candidate>& cands,
                           ConformityIndex& index);

}  // namespace hexfem
