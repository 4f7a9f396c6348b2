#include "mesher/recombine_hex.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

// Hex corners (Gmsh order): corner 0 has edges to 1, 3, 4; the other corners' edges, in the
// right-handed order of element_topology.hpp's corner table:
//   1:(2,0,5) 2:(3,1,6) 3:(0,2,7) 4:(7,5,0) 5:(4,6,1) 6:(5,7,2) 7:(6,4,3).
// From lowest vertex v = p0 and p1 < p3, p1 < p4 (one of the three rotations about p0), each hex
// has exactly one labelling, so each is found once.
void hexes_from(const TetTopology& topo, std::int32_t v, double qmin, FillScratch& scratch,
                const std::vector<char>* used, float keep_from, float keep_below,
                std::vector<HexCorners>& out) {
  const auto& X = topo.mesh().nodes;
  auto ok = [&](std::int32_t o, std::int32_t a, std::int32_t b, std::int32_t c) {
    return corner_at_least(X[o], X[a], X[b], X[c], qmin);
  };
  // The corner at v is three quad faces (v p1 p2 p3), (v p1 p5 p4), (v p3 p7 p4) pairwise
  // sharing an edge at v: triangles in the graph of v's edges linked by potential quads.
  quads_at(topo, v, qmin, scratch, used);
  const auto& Q = scratch.quads;
  const auto& K = scratch.keys;
  if (Q.empty()) return;
  if (scratch.near.size() != X.size()) scratch.near.assign(X.size(), 0);
  // The quads (v, a, x, b) of each pair a < b: a range of Q, in a table by the numbers of a and
  // b among v's neighbours above v.
  const std::size_t n = scratch.num_up;
  auto& range = scratch.ranges;
  range.assign(n * n, {0, 0});
  for (std::size_t i = 0; i < K.size();) {
    std::size_t e = i + 1;
    while (e < K.size() && K[e] >> 32 == K[i] >> 32) ++e;
    range[(K[i] >> 48) * n + (K[i] >> 32 & 0xffff)] = {static_cast<std::uint32_t>(i),
                                                       static_cast<std::uint32_t>(e)};
    i = e;
  }
  auto between = [&](std::size_t la, std::size_t lb) {  // la < lb
    const auto r = range[la * n + lb];
    return std::pair<const CornerQuad*, const CornerQuad*>{Q.data() + r[0], Q.data() + r[1]};
  };
  auto& sixth = scratch.sixth;
  for (std::size_t i = 0; i < Q.size();) {
    // Block of quads with a = p1; within it, pairs of distinct partners q < r.
    const std::int32_t p1 = Q[i].a;
    const std::size_t l1 = K[i] >> 48;
    std::size_t end = i;
    while (end < Q.size() && Q[end].a == p1) ++end;
    for (std::size_t j = i; j < end; ++j) {
      if (j > i && Q[j - 1].b == Q[j].b) continue;
      const std::int32_t q = Q[j].b;
      const std::size_t lq = K[j] >> 32 & 0xffff;
      for (std::size_t k = j + 1; k < end; ++k) {
        if (Q[k - 1].b == Q[k].b || Q[k].b == q) continue;
        const std::int32_t r = Q[k].b;
        const std::size_t lr = K[k] >> 32 & 0xffff;
        const auto qr = between(lq, lr);
        if (qr.first == qr.second) continue;
        // Orientation: (p1, p3, p4) right-handed at v.
        std::int32_t p3 = q, p4 = r;
        std::size_t l3 = lq, l4 = lr;
        if (!ok(v, p1, p3, p4)) {
          std::swap(p3, p4);
          std::swap(l3, l4);
          if (!ok(v, p1, p3, p4)) continue;
        }
        const auto c2 = between(l1, l3);
        const auto c5 = between(l1, l4);
        for (const CornerQuad* q2 = c2.first; q2 != c2.second; ++q2) {
          const std::int32_t p2 = q2->x;
          if (p2 == p4) continue;
          // p2's neighbours, marked for the p6 search below.
          const std::uint32_t epoch = next_near_epoch(scratch);
          for (auto it = topo.neighbours_begin(p2); it != topo.neighbours_end(p2); ++it)
            scratch.near[*it] = epoch;
          for (const CornerQuad* q5 = c5.first; q5 != c5.second; ++q5) {
            const std::int32_t p5 = q5->x;
            if (p5 == p2 || p5 == p3 || !ok(p1, p2, v, p5)) continue;
            bool sixth_known = false;  // p6 choices: adjacent to p2 and p5, found once per pair
            for (const CornerQuad* q7 = qr.first; q7 != qr.second; ++q7) {
              const std::int32_t p7 = q7->x;
              if (p7 == p1 || p7 == p2 || p7 == p5) continue;
              if (!ok(p3, v, p2, p7) || !ok(p4, p7, p5, v)) continue;
              if (!sixth_known) {
                sixth.clear();
                for (auto it =
                         std::upper_bound(topo.neighbours_begin(p5), topo.neighbours_end(p5), v);
                     it != topo.neighbours_end(p5); ++it) {
                  const std::int32_t p6 = *it;
                  if (scratch.near[p6] == epoch && p6 != p1 && p6 != p3 && p6 != p4 && p6 != p2)
                    sixth.push_back(p6);
                }
                sixth_known = true;
              }
              // p6: adjacent to p2, p5 and p7.
              for (const std::int32_t p6 : sixth) {
                if (p6 == p7 || !topo.adjacent(p7, p6)) continue;
                if (!ok(p2, p3, p1, p6) || !ok(p5, p4, p6, p1) || !ok(p6, p5, p7, p2) ||
                    !ok(p7, p6, p4, p3))
                  continue;
                // The three faces at p6 need a diagonal among the tet edges too.
                if (!topo.adjacent(p1, p6) && !topo.adjacent(p2, p5)) continue;
                if (!topo.adjacent(p3, p6) && !topo.adjacent(p2, p7)) continue;
                if (!topo.adjacent(p4, p6) && !topo.adjacent(p5, p7)) continue;
                HexCorners c;
                c.nodes = {v, p1, p2, p3, p4, p5, p6, p7};
                Vec3 x[8];
                for (int i8 = 0; i8 < 8; ++i8) x[i8] = X[c.nodes[i8]];
                c.quality = static_cast<float>(min_scaled_jacobian(CellKind::Hex8, x));
                if (!(c.quality >= keep_from && c.quality < keep_below)) continue;
                out.push_back(c);
              }
            }
          }
        }
      }
    }
    i = end;
  }
}

// The least scaled Jacobian a corner of a hex in the band can have. Every corner of a hex of
// quality q has at least q (the hex's is their minimum): a band's lower end prunes the search.
// Corners are computed with other rounding than the quality, hence the small allowance; the
// band itself is kept exactly.
double corner_floor(const HexOptions& options, const QualityBand& band) {
  return std::max(options.min_quality, static_cast<double>(band.from) - 1e-6);
}

// The free tets (used[t] == 0) at each vertex, as offsets into one list.
struct FreeStars {
  std::vector<std::int32_t> first, tets;
  FreeStars(const TetTopology& topo, const std::vector<char>& used) {
    const auto& T = topo.mesh().tets;
    first.assign(topo.num_vertices() + 1, 0);
    for (std::size_t t = 0; t < T.size(); ++t)
      if (!used[t])
        for (std::int32_t u : T[t]) ++first[u + 1];
    for (std::size_t v = 0; v + 1 < first.size(); ++v) first[v + 1] += first[v];
    tets.resize(first.back());
    std::vector<std::int32_t> at(first.begin(), first.end() - 1);
    for (std::size_t t = 0; t < T.size(); ++t)
      if (!used[t])
        for (std::int32_t u : T[t]) tets[at[u]++] = static_cast<std::int32_t>(t);
  }
};

// Whether a free tet has its four vertices among h's corners, not all on one face (a free tet
// on one face is a flat sliver there).
bool has_free_tet(const TetTopology& topo, const HexCorners& h, const FreeStars& free) {
  const auto& T = topo.mesh().tets;
  // The faces as masks of corners, from the hex's face table.
  static const std::array<unsigned, 6> kFace = [] {
    std::array<unsigned, 6> mask{};
    const CellFaces cf = faces_of(CellKind::Hex8);
    for (int f = 0; f < 6; ++f)
      for (int i = 0; i < cf.face[f].n; ++i) mask[f] |= 1u << cf.face[f].v[i];
    return mask;
  }();
  for (std::int32_t u : h.nodes)
    for (std::int32_t k = free.first[u]; k < free.first[u + 1]; ++k) {
      unsigned mask = 0;
      for (std::int32_t w : T[free.tets[k]]) {
        const auto at = std::find(h.nodes.begin(), h.nodes.end(), w);
        if (at == h.nodes.end()) {
          mask = 0;
          break;
        }
        mask |= 1u << (at - h.nodes.begin());
      }
      if (mask && std::find(kFace.begin(), kFace.end(), mask) == kFace.end()) return true;
    }
  return false;
}

// The hexes of each run at or above quality `from` (a prefix: runs are best first), as corners,
// added to kept as runs of their own.
template <class T>
void keep_from(const SortedRuns<T>& runs, float from, SortedRuns<HexCorners>& kept) {
  for (const auto& run : runs.runs) {
    const auto end =
        std::partition_point(run.begin(), run.end(), [&](const T& h) { return h.quality >= from; });
    if (end == run.begin()) continue;
    std::vector<HexCorners> top;
    top.reserve(static_cast<std::size_t>(end - run.begin()));
    for (auto it = run.begin(); it != end; ++it) top.push_back({it->quality, it->nodes});
    kept.runs.push_back(std::move(top));
  }
}

}  // namespace

SortedRuns<HexCorners> enumerate_hexes(const TetTopology& topo, const HexOptions& options,
                                       const QualityBand& band, const std::vector<char>* used) {
  const double corner_min = corner_floor(options, band);
  return find_sorted_runs<HexCorners>(
      static_cast<std::int32_t>(topo.num_vertices()),
      [&](std::int32_t v, FillScratch& scratch, std::vector<HexCorners>& out) {
        hexes_from(topo, v, corner_min, scratch, used, band.from, band.below, out);
      });
}

SortedRuns<Candidate> enumerate_filled_hexes(const TetTopology& topo, const HexOptions& options,
                                             const QualityBand& band, std::size_t* found) {
  const double corner_min = corner_floor(options, band);
  std::atomic<std::size_t> count{0};
  SortedRuns<Candidate> runs = find_sorted_runs<Candidate>(
      static_cast<std::int32_t>(topo.num_vertices()),
      [&](std::int32_t v, FillScratch& scratch, std::vector<Candidate>& out) {
        thread_local std::vector<HexCorners> hexes;
        hexes.clear();
        hexes_from(topo, v, corner_min, scratch, nullptr, band.from, band.below, hexes);
        if (!hexes.empty()) count.fetch_add(hexes.size(), std::memory_order_relaxed);
        for (const HexCorners& h : hexes) {
          Candidate c = h.candidate();
          if (fills_element(topo, c, nullptr, options.fill)) out.push_back(c);
        }
      });
  if (found) *found = count.load();
  return runs;
}

std::vector<Candidate> hex_candidate_list(const TetTopology& topo, const HexOptions& options) {
  const SortedRuns<HexCorners> runs = enumerate_hexes(topo, options);
  std::vector<Candidate> list;
  list.reserve(runs.size());
  RunMerger<HexCorners> merger(runs);
  while (const HexCorners* h = merger.next()) list.push_back(h->candidate());
  return list;
}

std::vector<Candidate> fillable_hex_list(const TetTopology& topo, const HexOptions& options,
                                         const QualityBand& band) {
  return merge_runs(enumerate_filled_hexes(topo, options, band));
}

std::vector<Candidate> hexes_holding_free_tets(const TetTopology& topo, const HexOptions& options,
                                               const SortedRuns<HexCorners>& found,
                                               const std::vector<char>& used) {
  const FreeStars free(topo, used);
  std::vector<HexCorners> near;
#pragma omp parallel
  {
    std::vector<HexCorners> mine;
    const auto nr = static_cast<std::ptrdiff_t>(found.runs.size());
#pragma omp for schedule(dynamic, 1) nowait
    for (std::ptrdiff_t r = 0; r < nr; ++r)
      for (const HexCorners& h : found.runs[r])
        if (has_free_tet(topo, h, free)) mine.push_back(h);
#pragma omp critical
    near.insert(near.end(), mine.begin(), mine.end());
  }
  // Fill tests in vertex order, where the tets around are in cache.
  std::sort(near.begin(), near.end(),
            [](const HexCorners& a, const HexCorners& b) { return a.nodes < b.nodes; });
  std::vector<Candidate> list(near.size());
  std::vector<char> fills(near.size(), 0);
  const auto n = static_cast<std::ptrdiff_t>(near.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    list[i] = near[i].candidate();
    fills[i] = fills_element(topo, list[i], nullptr, options.fill);
  }
  std::size_t k = 0;
  for (std::size_t i = 0; i < list.size(); ++i)
    if (fills[i]) list[k++] = list[i];
  list.resize(k);
  std::sort(list.begin(), list.end());
  return list;
}

std::vector<Candidate> hexes_holding_free_tets(const TetTopology& topo, const HexOptions& options,
                                               const QualityBand& band,
                                               const std::vector<char>& search_mask,
                                               const std::vector<char>& used) {
  const FreeStars free(topo, used);
  const double corner_min = corner_floor(options, band);
  // Most hexes found hold no free tet: tested where each is found, so only the few kept are
  // stored and sorted.
  return collect_candidates(static_cast<std::int32_t>(topo.num_vertices()),
                            [&](std::int32_t v, FillScratch& scratch, std::vector<Candidate>& out) {
                              thread_local std::vector<HexCorners> found;
                              found.clear();
                              hexes_from(topo, v, corner_min, scratch, &search_mask, band.from,
                                         band.below, found);
                              for (const HexCorners& h : found) {
                                if (!has_free_tet(topo, h, free)) continue;
                                Candidate c = h.candidate();
                                if (fills_element(topo, c, nullptr, options.fill)) out.push_back(c);
                              }
                            });
}

std::size_t place_hexes_greedily(RecombineState& s, const HexOptions& options,
                                 ConformityIndex& index, std::size_t* candidates,
                                 SortedRuns<HexCorners>* kept, float kept_from) {
  // The greedy order in bands of quality, best first: the best band is found and placed first;
  // each later band is then searched only among quads of free tets, since a hex with a used tet
  // can never be placed. Same hexes as one sorted list of every candidate, a fraction of the
  // enumeration on big parts (most candidates overlap hexes of a better band).
  std::size_t placed = 0;
  float below = std::numeric_limits<float>::infinity();
  for (std::size_t b = 0; b <= options.quality_bands.size(); ++b) {
    QualityBand band{-std::numeric_limits<float>::infinity(), below};
    if (b < options.quality_bands.size()) band.from = options.quality_bands[b];
    below = band.from;
    if (b == 0) {
      // The first band has most of the hexes (ANC101 at a million vertices: 1.00M of 1.25M):
      // fill-tested where they are found (enumerate_filled_hexes), twice as fast as in the
      // placement's best-first order, which reads the tets all over the part. The same hexes
      // are placed: the placement then only checks that their tets are free.
      std::size_t found = 0;
      const SortedRuns<Candidate> cands = enumerate_filled_hexes(s.topo, options, band, &found);
      if (candidates) *candidates += found;
      placed += place_greedily(s, cands, index);
      if (kept) keep_from(cands, kept_from, *kept);
      continue;
    }
    const SortedRuns<HexCorners> cands = enumerate_hexes(s.topo, options, band, &s.used);
    if (candidates) *candidates += cands.size();
    placed += place_greedily(s, cands, index);
    if (kept) keep_from(cands, kept_from, *kept);
  }
  return placed;
}

}  // namespace hexfem
