#include "mesher/recombine_place.hpp"

#include <algorithm>

#include "mesher/mesh/parallel.hpp"

namespace hexfem {

namespace {

constexpr std::size_t kChunk = 1 << 15;  // candidates fill-tested on all threads at a time

// A candidate with a corner whose tets are all taken cannot be placed any more.
bool corners_have_free_tets(const std::vector<std::int32_t>& free_around, const std::int32_t* nodes,
                            int n) {
  for (int i = 0; i < n; ++i)
    if (free_around[nodes[i]] == 0) return false;
  return true;
}

}  // namespace

template <class T>
SortedRuns<T> find_sorted_runs(std::int32_t num_vertices, const FindInto<T>& find) {
  // Each thread sorts its finds a block at a time: a buffer filled once, never grown by copying
  // (30M hex candidates on a 1M-vertex part), and sorts of cache-friendlier size.
  constexpr std::size_t kRun = std::size_t{1} << 22;
  SortedRuns<T> out;
#pragma omp parallel
  {
    std::vector<T> local;
    local.reserve(kRun);
    FillScratch scratch;
    auto flush = [&] {
      std::sort(local.begin(), local.end());
#pragma omp critical
      out.runs.push_back(std::move(local));
      local = {};
      local.reserve(kRun);
    };
#pragma omp for schedule(dynamic, 256) nowait
    for (std::int32_t v = 0; v < num_vertices; ++v) {
      find(v, scratch, local);
      if (local.size() >= kRun) flush();
    }
    if (!local.empty()) flush();
  }
  return out;
}
template SortedRuns<Candidate> find_sorted_runs(std::int32_t, const FindInto<Candidate>&);
template SortedRuns<HexCorners> find_sorted_runs(std::int32_t, const FindInto<HexCorners>&);

std::vector<Candidate> collect_candidates(std::int32_t num_vertices, const FindCandidates& find) {
  return merge_runs(find_sorted_runs<Candidate>(num_vertices, find));
}

std::vector<Candidate> merge_runs(const SortedRuns<Candidate>& r) {
  const auto& runs = r.runs;
  std::vector<Candidate> all;
  if (runs.size() == 2) {
    // Two runs (two threads): merged on all threads.
    const std::vector<Candidate>&A = runs[0], &B = runs[1];
    all.resize(A.size() + B.size());
    parallel_merge(A.data(), A.size(), B.data(), B.size(), all.data(), 2);
    return all;
  }
  RunMerger<Candidate> merger(r);
  all.reserve(r.size());
  while (const Candidate* c = merger.next()) all.push_back(*c);
  return all;
}

std::size_t place_greedily(RecombineState& s, const CandidateChunks& next, ConformityIndex& index) {
  const TetTopology& topo = s.topo;
  std::vector<char>& used = s.used;
  // Free tets around each vertex: a candidate with a corner whose tets are all taken cannot be
  // placed, and on big parts most candidates are rejected by this before any fill test.
  const TetMesh& m = topo.mesh();
  std::vector<std::int32_t> free_around(m.nodes.size(), 0);
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    if (!used[t])
      for (std::int32_t v : m.tets[t]) ++free_around[v];
  auto possible = [&](const Candidate& c) {
    return corners_have_free_tets(free_around, c.nodes.data(), num_nodes(c.kind));
  };
  // In chunks, best first: the fill tests of a chunk's still possible candidates on all threads
  // (they only read `used`), with the conformity rules against the elements placed before the
  // chunk; then the serial greedy pass over the chunk, which checks the rules against the
  // elements placed in it only (a candidate breaking them against earlier ones is out anyway).
  std::vector<Candidate> chunk;
  std::vector<char> fillable;
  std::vector<std::uint64_t> near;
  std::size_t kept = 0;
  for (;;) {
    chunk.clear();
    next(chunk, free_around);
    if (chunk.empty()) break;
    fillable.resize(chunk.size());
    const auto count = static_cast<std::ptrdiff_t>(chunk.size());
    const std::size_t before = index.size();
#pragma omp parallel
    {
      std::vector<std::uint64_t> near_local;
#pragma omp for schedule(dynamic, 256)
      for (std::ptrdiff_t k = 0; k < count; ++k) {
        Candidate& c = chunk[k];
        fillable[k] = possible(c) &&
                      (c.tets[0] >= 0 || fills_element(topo, c, &used, s.limits.fill)) &&
                      !index.conflicts(c, 0, near_local);
      }
    }
    // The pass waits on memory (the candidates lie all over the part): what a candidate a few
    // places ahead will read is asked for early.
    constexpr std::size_t kAhead = 8;
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      if (i + kAhead < chunk.size() && fillable[i + kAhead]) {
        const Candidate& a = chunk[i + kAhead];
        index.prefetch(a);
        for (int k = 0; k < num_nodes(a.kind); ++k) __builtin_prefetch(&free_around[a.nodes[k]]);
        for (std::int32_t t : a.tets)
          if (t >= 0) {
            __builtin_prefetch(&used[t]);
            __builtin_prefetch(&m.tets[t]);
          }
      }
      const Candidate& c = chunk[i];
      if (!fillable[i] || !possible(c)) continue;
      bool free = true;
      for (std::int32_t t : c.tets) free = free && (t < 0 || !used[t]);
      if (!free || index.conflicts(c, before, near)) continue;
      for (std::int32_t t : c.tets)
        if (t >= 0)
          for (std::int32_t v : m.tets[t]) --free_around[v];
      index.add(c);
      s.place(c);
      ++kept;
    }
  }
  s.debug_verify();
  return kept;
}

std::size_t place_greedily(RecombineState& s, std::vector<Candidate>& cands,
                           ConformityIndex& index) {
  if (!std::is_sorted(cands.begin(), cands.end())) std::sort(cands.begin(), cands.end());
  std::size_t at = 0;
  return place_greedily(
      s,
      [&](std::vector<Candidate>& chunk, const std::vector<std::int32_t>&) {
        const std::size_t end = std::min(cands.size(), at + kChunk);
        chunk.assign(cands.begin() + static_cast<std::ptrdiff_t>(at),
                     cands.begin() + static_cast<std::ptrdiff_t>(end));
        at = end;
      },
      index);
}

namespace {

int corners(const HexCorners&) {
  return 8;
}
int corners(const Candidate& c) {
  return num_nodes(c.kind);
}
Candidate as_candidate(const HexCorners& h) {
  return h.candidate();
}
const Candidate& as_candidate(const Candidate& c) {
  return c;
}

template <class T>
std::size_t place_runs(RecombineState& s, const SortedRuns<T>& cands, ConformityIndex& index) {
  RunMerger<T> merger(cands);
  return place_greedily(
      s,
      [&](std::vector<Candidate>& chunk, const std::vector<std::int32_t>& free_around) {
        // Most candidates late in the order have a corner with no free tet left: dropped here,
        // before they are copied and fill-tested.
        while (chunk.size() < kChunk) {
          const T* c = merger.next();
          if (!c) return;
          if (corners_have_free_tets(free_around, c->nodes.data(), corners(*c)))
            chunk.push_back(as_candidate(*c));
        }
      },
      index);
}

}  // namespace

std::size_t place_greedily(RecombineState& s, const SortedRuns<HexCorners>& cands,
                           ConformityIndex& index) {
  return place_runs(s, cands, index);
}

std::size_t place_greedily(RecombineState& s, const SortedRuns<Candidate>& cands,
                           ConformityIndex& index) {
  return place_runs(s, cands, index);
}

}  // namespace hexfem
