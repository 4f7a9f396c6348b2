#include "mesher/recombine_select.hpp"

#include <algorithm>
#include <array>

#include "mesher/mesh/error.hpp"
#include "mesher/recombine_rules.hpp"

namespace hexfem {

HexSelection parse_hex_selection(const std::string& name) {
  if (name == "greedy") return HexSelection::kGreedy;
  if (name == "swap") return HexSelection::kSwap;
  if (name == "swap-wide") return HexSelection::kSwapWide;
  throw Error("hex selection must be greedy, swap or swap-wide, got '" + name + "'");
}

namespace {

bool share_tet(const Candidate& a, const Candidate& b) {
  for (std::int32_t t : a.tets)
    if (t >= 0 && std::find(b.tets.begin(), b.tets.end(), t) != b.tets.end()) return true;
  return false;
}

struct Blockers {
  int n = 0;
  std::int32_t e[2] = {-1, -1};
};

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
  // The alive elements c conflicts with, ignoring gone0 and gone1: b.n = 0, 1 or 2 (in b.e),
  // 3 for three or more. Tets first: that answer costs no rule check.
  Blockers blockers(const Candidate& c, std::int32_t gone0, std::int32_t gone1,
                    std::vector<std::int32_t>& seen) const {
    Blockers b;
    auto skip = [&](std::int32_t e) {
      return e == gone0 || e == gone1 || (b.n >= 1 && e == b.e[0]) || (b.n == 2 && e == b.e[1]);
    };
    auto found = [&](std::int32_t e) {  // true when the answer is known: three or more
      if (b.n == 2) {
        b.n = 3;
        return true;
      }
      b.e[b.n++] = e;
      return false;
    };
    for (std::int32_t t : c.tets)
      if (t >= 0 && owner[t] >= 0 && !skip(owner[t]) && found(owner[t])) return b;
    seen.clear();
    for (int i = 0; i < num_nodes(c.kind); ++i)
      for (std::int32_t e : at[c.nodes[i]]) {
        if (skip(e) || std::find(seen.begin(), seen.end(), e) != seen.end()) continue;
        seen.push_back(e);
        if (rules_conflict(c, elems[e]) && found(e)) return b;
      }
    if (b.n == 2 && b.e[0] > b.e[1]) std::swap(b.e[0], b.e[1]);
    return b;
  }
};

}  // namespace

bool compatible(const Candidate& a, const Candidate& b) {
  return !share_tet(a, b) && !rules_conflict(a, b);
}

namespace {

// The largest set of pairwise compatible candidates among L (pool indices, best first) that
// the best-first completion of one start finds; the first start wins ties. In `best`, as
// indices into L.
void choose_compatible(const std::vector<Candidate>& pool, const std::vector<std::int32_t>& L,
                       std::vector<std::int32_t>& best) {
  const std::size_t m = L.size();
  std::vector<char> ok(m * m, 0);
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = a + 1; b < m; ++b)
      ok[a * m + b] = ok[b * m + a] = compatible(pool[L[a]], pool[L[b]]);
  best.clear();
  std::vector<std::int32_t> cur;
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
}

// The tet across face f of tet t (faces as in wide_swap_search_mask), or -1.
std::int32_t across(const RecombineState& s, std::int32_t t, int f) {
  const auto& T = s.topo.mesh().tets[t];
  return s.topo.tet_across(t, T[f], T[(f + 1) % 4], T[(f + 2) % 4]);
}

// The free tets (used[t] == 0) in increasing order, and the tets across their four faces (-1:
// none), found on all threads: each is a walk around a star, most of the search mask's time.
struct FreeTets {
  std::vector<std::int32_t> tets;
  std::vector<std::array<std::int32_t, 4>> across;
  explicit FreeTets(const RecombineState& s) {
    const auto nt = static_cast<std::int32_t>(s.used.size());
    for (std::int32_t t = 0; t < nt; ++t)
      if (!s.used[t]) tets.push_back(t);
    across.resize(tets.size());
    const auto n = static_cast<std::ptrdiff_t>(tets.size());
#pragma omp parallel for schedule(dynamic, 1024)
    for (std::ptrdiff_t i = 0; i < n; ++i)
      for (int f = 0; f < 4; ++f) across[i][f] = hexfem::across(s, tets[i], f);
  }
};

// The free tets whose component of free tets (joined through shared triangles) holds one that is
// not a sliver flat on a quad face of an element next to it, as flags on free.tets. Most free
// tets at a million vertices are such slivers between two hexes' faces, in components of their
// own; left out, they halve the tets wide_swap_search_mask opens.
std::vector<char> free_tets_with_a_solid_neighbourhood(const RecombineState& s,
                                                       const std::vector<std::int32_t>& owner,
                                                       const FreeTets& free) {
  const auto& T = s.topo.mesh().tets;
  const auto n = static_cast<std::int32_t>(free.tets.size());
  std::vector<char> sliver(free.tets.size(), 0);
#pragma omp parallel for schedule(dynamic, 1024)
  for (std::int32_t i = 0; i < n; ++i)
    for (std::int32_t t : free.across[i])
      if (t >= 0 && owner[t] >= 0) {
        const Candidate& e = s.elements[owner[t]];
        if (is_face_sliver(e.kind, e.nodes.data(), T[free.tets[i]])) {
          sliver[i] = 1;
          break;
        }
      }
  // Each free tet's place in free.tets, to walk the components.
  std::vector<std::int32_t> index(T.size(), -1);
  for (std::int32_t i = 0; i < n; ++i) index[free.tets[i]] = i;
  std::vector<char> keep(free.tets.size(), 0), seen(free.tets.size(), 0);
  std::vector<std::int32_t> stack, component;
  for (std::int32_t i0 = 0; i0 < n; ++i0) {
    if (seen[i0]) continue;
    bool solid = false;
    component.clear();
    stack.assign(1, i0);
    seen[i0] = 1;
    while (!stack.empty()) {
      const std::int32_t i = stack.back();
      stack.pop_back();
      component.push_back(i);
      solid = solid || !sliver[i];
      for (std::int32_t t : free.across[i]) {
        const std::int32_t j = t >= 0 ? index[t] : -1;
        if (j >= 0 && !seen[j]) {
          seen[j] = 1;
          stack.push_back(j);
        }
      }
    }
    if (solid)
      for (std::int32_t i : component) keep[i] = 1;
  }
  return keep;
}

}  // namespace

std::vector<char> wide_swap_search_mask(const RecombineState& s) {
  const std::vector<std::int32_t> owner = s.element_of_tets();
  const FreeTets free(s);
  const std::vector<char> from = free_tets_with_a_solid_neighbourhood(s, owner, free);
  std::vector<char> open(s.elements.size(), 0);
  for (std::size_t i = 0; i < free.tets.size(); ++i) {
    if (!from[i]) continue;
    for (std::int32_t n : free.across[i])
      if (n >= 0 && owner[n] >= 0) open[owner[n]] = 1;
  }
  std::vector<char> mask = s.used;
  for (std::size_t e = 0; e < s.elements.size(); ++e)
    if (open[e])
      for (std::int32_t t : s.elements[e].tets)
        if (t >= 0) mask[t] = 0;
  return mask;
}

std::vector<Candidate> swap_pool(const TetTopology& topo, const HexOptions& hex,
                                 const SwapOptions& o) {
  return fillable_hex_list(topo, hex, QualityBand{static_cast<float>(o.min_quality)});
}

SwapReport improve_by_swaps(RecombineState& s, const std::vector<Candidate>& pool,
                            const SwapOptions& o) {
  SwapReport rep;
  const TetTopology& topo = s.topo;
  Placement p;
  p.owner.assign(s.used.size(), -1);
  p.at.resize(topo.mesh().nodes.size());
  const std::size_t n0 = s.elements.size();
  {
    // Each vertex's list sized once (a million vertices: growing them one element at a time was
    // most of this setup), with room for two swapped in.
    std::vector<std::int32_t> count(p.at.size(), 2);
    for (const Candidate& e : s.elements)
      for (int i = 0; i < num_nodes(e.kind); ++i) ++count[e.nodes[i]];
    for (std::size_t v = 0; v < p.at.size(); ++v) p.at[v].reserve(count[v]);
    p.elems.reserve(n0 + n0 / 8);
    p.alive.reserve(n0 + n0 / 8);
    p.pool_index.reserve(n0 + n0 / 8);
  }
  for (const Candidate& e : s.elements) p.add(e, -1);

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

  // The candidates at each vertex, to find those whose blockers a change may have changed
  // (an element blocks a candidate only when they share a tet or two vertices).
  std::vector<std::int32_t> pool_first(p.at.size() + 1, 0), pool_at;
  for (const Candidate& c : pool)
    for (int i = 0; i < num_nodes(c.kind); ++i) ++pool_first[c.nodes[i] + 1];
  for (std::size_t v = 0; v < p.at.size(); ++v) pool_first[v + 1] += pool_first[v];
  pool_at.resize(pool_first.back());
  {
    std::vector<std::int32_t> fill_at(pool_first.begin(), pool_first.end() - 1);
    for (std::size_t i = 0; i < pool.size(); ++i)
      for (int k = 0; k < num_nodes(pool[i].kind); ++k)
        pool_at[fill_at[pool[i].nodes[k]]++] = static_cast<std::int32_t>(i);
  }
  std::vector<std::int32_t> dirty(pool.size());
  for (std::size_t i = 0; i < pool.size(); ++i) dirty[i] = static_cast<std::int32_t>(i);
  std::vector<char> marked(pool.size(), 0);
  std::vector<std::int32_t> touched;  // vertices of the elements put in or taken out
  auto touch = [&](const Candidate& c) {
    for (int k = 0; k < num_nodes(c.kind); ++k) touched.push_back(c.nodes[k]);
  };

  std::vector<Blockers> block(pool.size());
  std::vector<std::int32_t> seen;
  std::vector<std::pair<std::int32_t, std::int32_t>> one;  // (blocker, candidate)
  std::vector<std::array<std::int32_t, 3>> two;            // (blocker, blocker, candidate)
  std::vector<std::int32_t> L, best;
  // Puts in best (indices into L) in place of the elements `out` when each is still blocked by
  // those alone and at least `need` remain.
  auto try_swap = [&](std::int32_t g0, std::int32_t g1, std::size_t need) {
    std::erase_if(best, [&](std::int32_t x) {
      return in[L[x]] >= 0 || p.blockers(pool[L[x]], g0, g1, seen).n != 0;
    });
    if (best.size() < need) return false;
    for (std::int32_t g : {g0, g1})
      if (g >= 0) {
        touch(p.elems[g]);
        remove(g);
      }
    for (std::int32_t x : best) {
      insert(static_cast<std::size_t>(L[x]));
      touch(pool[L[x]]);
    }
    ++rep.swaps;
    return true;
  };
  auto range_of = [&](std::int32_t P) {
    auto lo = std::lower_bound(one.begin(), one.end(), std::pair{P, -1});
    auto hi = lo;
    while (hi != one.end() && hi->first == P) ++hi;
    return std::pair{lo, hi};
  };

  for (int round = 0; round < o.max_rounds && !dirty.empty(); ++round) {
    ++rep.rounds;
    // The blockers of the candidates whose neighbourhood changed (read-only, all threads).
    const auto nd = static_cast<std::ptrdiff_t>(dirty.size());
#pragma omp parallel
    {
      std::vector<std::int32_t> seen_local;
#pragma omp for schedule(dynamic, 1024)
      for (std::ptrdiff_t k = 0; k < nd; ++k) {
        const std::int32_t i = dirty[k];
        block[i] = Blockers{3, {-1, -1}};
        if (in[i] < 0 && eligible[i]) block[i] = p.blockers(pool[i], -1, -1, seen_local);
      }
    }
    touched.clear();
    // Candidates blocked by nothing (room a swap freed): put in, best first, each checked
    // against what was put in before it.
    for (std::size_t i = 0; i < pool.size(); ++i)
      if (block[i].n == 0 && in[i] < 0 && p.blockers(pool[i], -1, -1, seen).n == 0) {
        insert(i);
        touch(pool[i]);
      }
    // 1-for-k: the candidates blocked by one element only, grouped by it (best first within).
    one.clear();
    two.clear();
    for (std::size_t i = 0; i < pool.size(); ++i) {
      const auto ii = static_cast<std::int32_t>(i);
      if (block[i].n == 1) one.push_back({block[i].e[0], ii});
      if (block[i].n == 2) two.push_back({block[i].e[0], block[i].e[1], ii});
    }
    std::sort(one.begin(), one.end());
    std::sort(two.begin(), two.end());
    for (auto g = one.begin(); g != one.end();) {
      const std::int32_t P = g->first;
      const auto [lo, hi] = range_of(P);
      g = hi;
      if (hi - lo < 2 || !p.alive[P]) continue;
      L.clear();
      for (auto it = lo; it != hi && L.size() < o.max_partners; ++it) L.push_back(it->second);
      choose_compatible(pool, L, best);
      if (best.size() >= 2) try_swap(P, -1, 2);
    }
    // 2-for-k (k >= 3): the candidates blocked by a pair of elements, with those blocked by
    // either alone.
    for (std::size_t g = 0; o.pair_swaps && g < two.size();) {
      const std::int32_t P0 = two[g][0], P1 = two[g][1];
      L.clear();
      for (; g < two.size() && two[g][0] == P0 && two[g][1] == P1; ++g)
        if (L.size() < o.max_pair_partners) L.push_back(two[g][2]);
      if (!p.alive[P0] || !p.alive[P1]) continue;
      for (std::int32_t P : {P0, P1}) {
        const auto [lo, hi] = range_of(P);
        for (auto it = lo; it != hi && it - lo < static_cast<std::ptrdiff_t>(o.max_pair_partners);
             ++it)
          L.push_back(it->second);
      }
      if (L.size() < 3) continue;
      std::sort(L.begin(), L.end());  // best first
      choose_compatible(pool, L, best);
      if (best.size() >= 3) try_swap(P0, P1, 3);
    }
    // The next round looks again only at the candidates around what changed.
    dirty.clear();
    for (std::int32_t v : touched)
      for (std::int32_t k = pool_first[v]; k < pool_first[v + 1]; ++k)
        if (!marked[pool_at[k]]) {
          marked[pool_at[k]] = 1;
          dirty.push_back(pool_at[k]);
        }
    std::sort(dirty.begin(), dirty.end());
    for (std::int32_t i : dirty) marked[i] = 0;
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
