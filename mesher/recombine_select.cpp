#include "mesher/recombine_select.hpp"

#include <algorithm>

#include "mesher/mesh/error.hpp"
#include "mesher/recombine_rules.hpp"

namespace hexfem {

HexSelection parse_hex_selection(const std::string& name) {
  if (name == "greedy") return HexSelection::kGreedy;
  if (name == "swap") return HexSelection::kSwap;
  throw Error("hex selection must be greedy or swap, got '" + name + "'");
}

namespace {

bool share_tet(const Candidate& a, const Candidate& b) {
  for (std::int32_t t : a.tets)
    if (t >= 0 && std::find(b.tets.begin(), b.tets.end(), t) != b.tets.end()) return true;
  return false;
}

// The conformity rules between two elements, through ConformityIndex itself (so the rules are
// exactly the greedy pass's) on vertices renumbered 0..15: the index then stays a few entries
// long instead of one per mesh vertex.
bool rules_conflict(const Candidate& a, const Candidate& b) {
  std::int32_t ids[16];
  int n = 0;
  auto local = [&](std::int32_t v) {
    for (int i = 0; i < n; ++i)
      if (ids[i] == v) return i;
    ids[n] = v;
    return n++;
  };
  Candidate la = a, lb = b;
  const int na = num_nodes(a.kind), nb = num_nodes(b.kind);
  for (int i = 0; i < na; ++i) la.nodes[i] = local(a.nodes[i]);
  for (int i = 0; i < nb; ++i) lb.nodes[i] = local(b.nodes[i]);
  if (n > na + nb - 2) return false;  // every rule needs two shared vertices
  ConformityIndex index;
  index.add(lb);
  return index.conflicts(la);
}

// The elements placed so far, by a stable id (dead ones stay listed), with the tet -> element
// and vertex -> elements maps the conflict queries need.
struct Placement {
  std::vector<Candidate> elems;
  std::vector<char> alive;
  std::vector<std::int32_t> pool_index;       // the candidate an element is, or -1
  std::vector<std::int32_t> owner;            // tet -> alive element, or -1
  std::vector<std::vector<std::int32_t>> at;  // vertex -> alive elements

  std::int32_t add(const Candidate& c, std::int32_t from_pool) {
    const auto id = static_cast<std::int32_t>(elems.size());
    elems.push_back(c);
    alive.push_back(1);
    pool_index.push_back(from_pool);
    for (std::int32_t t : c.tets)
      if (t >= 0) owner[t] = id;
    for (int i = 0; i < num_nodes(c.kind); ++i) at[c.nodes[i]].push_back(id);
    return id;
  }
  void kill(std::int32_t id) {
    alive[id] = 0;
    const Candidate& c = elems[id];
    for (std::int32_t t : c.tets)
      if (t >= 0) owner[t] = -1;
    for (int i = 0; i < num_nodes(c.kind); ++i) {
      auto& list = at[c.nodes[i]];
      list.erase(std::find(list.begin(), list.end(), id));
    }
  }
  // The alive elements c conflicts with, ignoring `gone`: returns 0, 1 (in out) or 2 (two or
  // more). Tets first: that answer costs no rule check.
  int conflicts(const Candidate& c, std::int32_t& out, std::int32_t gone,
                std::vector<std::int32_t>& seen) const {
    int n = 0;
    out = -1;
    auto found = [&](std::int32_t e) {
      if (e == gone || (n == 1 && e == out)) return false;
      if (n++ == 0) out = e;
      return n == 2;
    };
    for (std::int32_t t : c.tets)
      if (t >= 0 && owner[t] >= 0 && found(owner[t])) return 2;
    seen.clear();
    for (int i = 0; i < num_nodes(c.kind); ++i)
      for (std::int32_t e : at[c.nodes[i]]) {
        if (e == gone || (n == 1 && e == out)) continue;
        if (std::find(seen.begin(), seen.end(), e) != seen.end()) continue;
        seen.push_back(e);
        if (rules_conflict(c, elems[e]) && found(e)) return 2;
      }
    return n;
  }
};

}  // namespace

bool compatible(const Candidate& a, const Candidate& b) {
  return !share_tet(a, b) && !rules_conflict(a, b);
}

SwapReport improve_by_swaps(RecombineState& s, const std::vector<Candidate>& cands,
                            const SwapOptions& o) {
  SwapReport rep;
  const TetTopology& topo = s.topo;
  Placement p;
  p.owner.assign(s.used.size(), -1);
  p.at.resize(topo.mesh().nodes.size());
  const std::size_t n0 = s.elements.size();
  for (const Candidate& e : s.elements) p.add(e, -1);

  // The pool: every candidate that tets fill, placed or not, best first (cands' order). The
  // fill test without `used` on all threads, in chunks to bound the copies.
  std::vector<Candidate> pool;
  constexpr std::size_t kChunk = 1 << 16;
  std::vector<Candidate> chunk;
  std::vector<char> fills;
  for (std::size_t start = 0; start < cands.size(); start += kChunk) {
    const std::size_t end = std::min(cands.size(), start + kChunk);
    const auto count = static_cast<std::ptrdiff_t>(end - start);
    chunk.assign(cands.begin() + static_cast<std::ptrdiff_t>(start),
                 cands.begin() + static_cast<std::ptrdiff_t>(end));
    fills.assign(chunk.size(), 0);
#pragma omp parallel for schedule(dynamic, 256)
    for (std::ptrdiff_t k = 0; k < count; ++k)
      fills[k] = fills_element(topo, chunk[k], nullptr, s.limits.fill);
    for (std::ptrdiff_t k = 0; k < count; ++k)
      if (fills[k]) pool.push_back(chunk[k]);
  }
  rep.fillable = pool.size();
  // Which of them greedy placed; the others count only above the swap's quality floor.
  std::vector<std::int32_t> in(pool.size(), -1);
  std::vector<char> eligible(pool.size(), 0);
  for (std::size_t i = 0; i < pool.size(); ++i) {
    const Candidate& c = pool[i];
    const std::int32_t e = c.tets[0] >= 0 ? p.owner[c.tets[0]] : -1;
    if (e >= 0 && p.elems[e].nodes == c.nodes) {
      in[i] = e;
      p.pool_index[e] = static_cast<std::int32_t>(i);
    }
    eligible[i] = in[i] >= 0 || c.quality >= o.min_quality;
  }

  auto insert = [&](std::size_t i) {
    in[i] = p.add(pool[i], static_cast<std::int32_t>(i));
    ++rep.inserted;
  };
  auto remove = [&](std::int32_t e) {
    p.kill(e);
    if (p.pool_index[e] >= 0) in[p.pool_index[e]] = -1;
    ++rep.removed;
  };

  std::vector<std::int32_t> tight(pool.size());
  std::vector<std::int8_t> num(pool.size());
  std::vector<std::int32_t> seen;
  for (int round = 0; round < o.max_rounds; ++round) {
    ++rep.rounds;
    // Every free candidate's conflicts with the placed elements (read-only, all threads).
    const auto np = static_cast<std::ptrdiff_t>(pool.size());
#pragma omp parallel
    {
      std::vector<std::int32_t> seen_local;
#pragma omp for schedule(dynamic, 1024)
      for (std::ptrdiff_t i = 0; i < np; ++i) {
        num[i] = 2;
        if (in[i] < 0 && eligible[i])
          num[i] = static_cast<std::int8_t>(p.conflicts(pool[i], tight[i], -1, seen_local));
      }
    }
    std::size_t changes = 0;
    // Candidates with no conflict left (room a swap freed): put in, best first, each checked
    // against what was put in before it.
    std::int32_t dummy;
    for (std::size_t i = 0; i < pool.size(); ++i)
      if (num[i] == 0 && p.conflicts(pool[i], dummy, -1, seen) == 0) {
        insert(i);
        ++changes;
      }
    // Candidates blocked by one element only, grouped by that element (best first within).
    std::vector<std::pair<std::int32_t, std::int32_t>> groups;
    for (std::size_t i = 0; i < pool.size(); ++i)
      if (num[i] == 1) groups.push_back({tight[i], static_cast<std::int32_t>(i)});
    std::sort(groups.begin(), groups.end());
    std::vector<std::int32_t> L, best, cur;
    std::vector<char> ok;
    for (std::size_t g = 0; g < groups.size();) {
      std::size_t ge = g;
      while (ge < groups.size() && groups[ge].first == groups[g].first) ++ge;
      const std::int32_t P = groups[g].first;
      L.clear();
      for (std::size_t k = g; k < ge && L.size() < o.max_partners; ++k)
        L.push_back(groups[k].second);
      g = ge;
      if (L.size() < 2 || !p.alive[P]) continue;
      // Pairwise compatibility, then from each start the best-first maximal compatible set;
      // the largest wins (the first on ties).
      const std::size_t m = L.size();
      ok.assign(m * m, 0);
      for (std::size_t a = 0; a < m; ++a)
        for (std::size_t b = a + 1; b < m; ++b)
          ok[a * m + b] = ok[b * m + a] = compatible(pool[L[a]], pool[L[b]]);
      best.clear();
      for (std::size_t a = 0; a < m; ++a) {
        cur.assign(1, static_cast<std::int32_t>(a));
        for (std::size_t b = 0; b < m; ++b) {
          if (b == a) continue;
          bool fits = true;
          for (std::int32_t x : cur) fits = fits && ok[static_cast<std::size_t>(x) * m + b];
          if (fits) cur.push_back(static_cast<std::int32_t>(b));
        }
        if (cur.size() > best.size()) best = cur;
      }
      if (best.size() < 2) continue;
      // Still blocked by P alone, now that earlier swaps of this round are done?
      std::erase_if(best, [&](std::int32_t x) {
        std::int32_t other;
        return in[L[x]] >= 0 || p.conflicts(pool[L[x]], other, P, seen) != 0;
      });
      if (best.size() < 2) continue;
      remove(P);
      for (std::int32_t x : best) insert(static_cast<std::size_t>(L[x]));
      ++rep.swaps;
      ++changes;
    }
    if (!changes) break;
  }

  // Back into the state: the greedy elements still there in their order, then the new ones.
  std::vector<char> drop(n0, 0);
  for (std::size_t e = 0; e < n0; ++e) drop[e] = !p.alive[e];
  s.remove(drop);
  for (std::size_t e = n0; e < p.elems.size(); ++e)
    if (p.alive[e]) s.place(p.elems[e]);
  s.debug_verify();
  return rep;
}

}  // namespace hexfem
