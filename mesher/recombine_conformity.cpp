#include "mesher/recombine_conformity.hpp"

#include <algorithm>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/recombine_prism_pyramid.hpp"

namespace hexfem {

namespace {

// What lies across quad face f of an element: another element's quad (and which of its faces),
// the surface, or tets (NC).
constexpr std::int32_t kSurface = -2, kTets = -1;
struct Across {
  std::int32_t element = kTets;
  std::int8_t face = -1;
};

// Quad face f of e lies on the surface: its two triangles, split along either diagonal, are
// surface triangles.
bool quad_on_surface(const TetTopology& topo, const Candidate& e, int f) {
  const QuadKey q = quad_corners(e, f);
  return (topo.surface_triangle(q[0], q[1], q[2]) >= 0 &&
          topo.surface_triangle(q[0], q[2], q[3]) >= 0) ||
         (topo.surface_triangle(q[0], q[1], q[3]) >= 0 &&
          topo.surface_triangle(q[1], q[2], q[3]) >= 0);
}

// across[6 * i + f] for every quad face f of every element i.
std::vector<Across> faces_across(const TetTopology& topo, const std::vector<Candidate>& elements) {
  struct Owner {
    QuadKey key;
    std::int32_t element;
    std::int8_t face;
    bool operator<(const Owner& o) const {
      for (int i = 0; i < 4; ++i)
        if (key[i] != o.key[i]) return key[i] < o.key[i];
      return element < o.element;
    }
  };
  std::vector<Owner> owners;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const CellFaces cf = faces_of(elements[i].kind);
    for (int f = 0; f < cf.count; ++f)
      if (cf.face[f].n == 4)
        owners.push_back(
            {quad_key(elements[i], f), static_cast<std::int32_t>(i), static_cast<std::int8_t>(f)});
  }
  std::sort(owners.begin(), owners.end());
  std::vector<Across> across(6 * elements.size());
  for (std::size_t a = 0; a < owners.size();) {
    std::size_t b = a + 1;
    while (b < owners.size() && owners[b].key == owners[a].key) ++b;
    if (b - a == 2) {
      across[6 * owners[a].element + owners[a].face] = {owners[a + 1].element, owners[a + 1].face};
      across[6 * owners[a + 1].element + owners[a + 1].face] = {owners[a].element, owners[a].face};
    } else if (b - a == 1 && quad_on_surface(topo, elements[owners[a].element], owners[a].face)) {
      across[6 * owners[a].element + owners[a].face].element = kSurface;
    }
    a = b;
  }
  return across;
}

std::size_t count_nc(const std::vector<Candidate>& elements, const std::vector<Across>& across,
                     const std::vector<char>& gone) {
  std::size_t nc = 0;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    if (gone[i]) continue;
    const CellFaces cf = faces_of(elements[i].kind);
    for (int f = 0; f < cf.count; ++f)
      nc += cf.face[f].n == 4 && across[6 * i + f].element == kTets;
  }
  return nc;
}

bool has_vertex(const std::array<std::int32_t, 4>& T, std::int32_t v) {
  return T[0] == v || T[1] == v || T[2] == v || T[3] == v;
}

// The pyramid on quad q (in the outward order of the element it rests on) made of the two tets
// on its triangles split along diagonal d (0: q0-q2, 1: q1-q3), found by tet_on(triangle)
// (a tet with that face, or -1): they must share their fourth vertex, which is no corner of q
// (a flat tet on the face), lie in one solid, and make a pyramid of at least min_quality.
template <class TetOn>
bool pyramid_on(const TetTopology& topo, const std::int32_t* q, int d, TetOn tet_on,
                double min_quality, Candidate& out) {
  const std::int32_t tri[2][3] = {{q[d], q[d + 1], q[d + 2]}, {q[d + 2], q[(d + 3) % 4], q[d]}};
  std::int32_t tet[2], apex[2] = {-1, -1};
  for (int s = 0; s < 2; ++s) {
    tet[s] = tet_on(tri[s]);
    if (tet[s] < 0) return false;
    for (std::int32_t w : topo.mesh().tets[tet[s]])
      if (w != tri[s][0] && w != tri[s][1] && w != tri[s][2]) apex[s] = w;
  }
  if (tet[0] == tet[1] || apex[0] != apex[1] ||
      topo.mesh().tet_solid[tet[0]] != topo.mesh().tet_solid[tet[1]])
    return false;
  for (int k = 0; k < 4; ++k)
    if (q[k] == apex[0]) return false;
  out.kind = CellKind::Pyramid5;
  out.nodes = {q[0], q[1], q[2], q[3], apex[0], -1, -1, -1};
  out.tets = {std::min(tet[0], tet[1]), std::max(tet[0], tet[1]), -1, -1, -1, -1, -1};
  Vec3 x[5];
  for (int i = 0; i < 5; ++i) x[i] = topo.mesh().nodes[out.nodes[i]];
  const double qual = min_scaled_jacobian(CellKind::Pyramid5, x);
  out.quality = static_cast<float>(qual);
  return qual > 0 && qual >= min_quality;
}

bool has_triangle(const std::array<std::int32_t, 4>& T, const std::int32_t* tri) {
  return has_vertex(T, tri[0]) && has_vertex(T, tri[1]) && has_vertex(T, tri[2]);
}

// The pyramid that e's own tets on its quad face f make on the matching face pf of partner p
// once e is undone (base in p's outward order, apex inside e). Tets of e already taken by
// another such pyramid (taken[0..n)) are not reused. A face with a sliver between the two
// elements' diagonals gets none here (the final pyramid pass handles it).
bool pyramid_behind(const TetTopology& topo, const Candidate& e, int f, const Candidate& p, int pf,
                    double min_quality, const std::int32_t* taken, int n, Candidate& out) {
  const QuadKey q = quad_corners(p, pf);
  const int d = quad_diagonal(topo, p, pf);
  const LocalFace ef = faces_of(e.kind).face[f];
  const int de = quad_diagonal(topo, e, f);
  const std::int32_t pd[2] = {q[d], q[d + 2]}, ed[2] = {e.nodes[ef.v[de]], e.nodes[ef.v[de + 2]]};
  if (!((pd[0] == ed[0] && pd[1] == ed[1]) || (pd[0] == ed[1] && pd[1] == ed[0]))) return false;
  auto own_tet = [&](const std::int32_t* tri) {
    for (std::int32_t t : e.tets)
      if (t >= 0 && std::find(taken, taken + n, t) == taken + n &&
          has_triangle(topo.mesh().tets[t], tri))
        return t;
    return std::int32_t{-1};
  };
  return pyramid_on(topo, q.data(), d, own_tet, min_quality, out);
}

struct Undo {
  int gain;
  float quality;
  std::int32_t element;
  bool operator<(const Undo& o) const {
    if (gain != o.gain) return gain > o.gain;
    if (quality != o.quality) return quality < o.quality;
    return element < o.element;
  }
};

// True when the two free tets across quad face f of c (split along c's diagonal) make a
// pyramid of at least min_quality on it: the final pyramid pass can then match the face.
bool pyramid_possible(const TetTopology& topo, const Candidate& c, int f,
                      const std::vector<char>& used, double min_quality) {
  const QuadKey q = quad_corners(c, f);
  auto free_tet = [&](const std::int32_t* tri) {
    for (auto it = topo.star_begin(tri[0]); it != topo.star_end(tri[0]); ++it)
      if (has_triangle(topo.mesh().tets[*it], tri) &&
          std::find(c.tets.begin(), c.tets.end(), *it) == c.tets.end())
        return used[*it] ? std::int32_t{-1} : *it;
    return std::int32_t{-1};
  };
  Candidate unused;
  return pyramid_on(topo, q.data(), quad_diagonal(topo, c, f), free_tet, min_quality, unused);
}

// Prisms in the gaps between elements, made of free tets and of the tets of whole two-tet
// pyramids: a prism whose quad faces match NC faces of hexes or prisms replaces the pyramid on
// one of them and matches the others (where two hexes meet at an edge with a wedge of tets
// between them, the pyramid on one face leaves the other NC). Kept, best gain first then best
// quality, when it lowers the NC count: +1 for each NC face of an element it matches, -1 for
// each of its own quad faces left facing tets and for each pyramid it takes whose base it does
// not match. Returns how many were made; r.undone counts the pyramids taken.
// The elements (gone ones skipped) and what lies across their quad faces are kept up to date;
// `around` receives the new prisms and the elements they match (whose faces may now hold a
// sliver to absorb).
std::size_t prisms_in_gaps(const TetTopology& topo, std::vector<Candidate>& elements,
                           std::vector<Across>& across, std::vector<char>& gone,
                           std::vector<char>& used, const PrismOptions& options, double min_pyramid,
                           NcRepair& r, std::vector<Candidate>& around) {
  std::vector<char> soft = used;  // pyramid tets count as free
  std::vector<std::int32_t> pyramid_of(used.size(), -1);
  ConformityIndex index;
  std::vector<std::pair<QuadKey, std::int32_t>> owner;  // quad faces of hexes and prisms
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const Candidate& e = elements[i];
    if (gone[i]) continue;
    if (e.kind == CellKind::Pyramid5) {
      if (e.tets[2] >= 0) continue;  // it holds a sliver: left alone
      for (int k = 0; k < 2; ++k) {
        soft[e.tets[k]] = 0;
        pyramid_of[e.tets[k]] = static_cast<std::int32_t>(i);
      }
      continue;
    }
    // Only faces facing tets or a pyramid: a candidate cannot have a face matched by two
    // elements already (the tets on both sides are taken).
    const CellFaces cf = faces_of(e.kind);
    for (int f = 0; f < cf.count; ++f) {
      const std::int32_t o = cf.face[f].n == 4 ? across[6 * i + f].element : kSurface;
      if (o == kTets || (o >= 0 && elements[o].kind == CellKind::Pyramid5))
        owner.push_back({quad_key(e, f), static_cast<std::int32_t>(6 * i + f)});
    }
  }
  std::sort(owner.begin(), owner.end());
  std::vector<std::pair<QuadKey, std::int32_t>> added;  // quad faces of the new prisms, sorted
  auto owner_of = [&](const QuadKey& k) {
    for (const auto* v : {&owner, &added}) {
      auto it = std::lower_bound(v->begin(), v->end(), std::make_pair(k, -1));
      if (it != v->end() && it->first == k) return it->second;
    }
    return -1;
  };
  // Candidates: prisms with two of these faces, one of them NC, meeting at an edge (u, v) (the
  // wedge of tets between two elements); their lateral edge u-v is the prism's edge 0-3.
  auto corners = [&](std::int32_t o) { return quad_corners(elements[o / 6], o % 6); };
  std::vector<std::pair<std::uint64_t, std::int32_t>> by_edge;  // (edge, owner face)
  for (const auto& [key, o] : owner) {
    const QuadKey q = corners(o);
    for (int k = 0; k < 4; ++k) by_edge.push_back({edge_key(q[k], q[(k + 1) % 4]), o});
  }
  std::sort(by_edge.begin(), by_edge.end());
  std::vector<Candidate> cands;
  const auto& X = topo.mesh().nodes;
  for (const auto& [key, o] : owner) {
    if (across[o].element != kTets) continue;
    const QuadKey q = corners(o);
    for (int k = 0; k < 4; ++k) {
      std::int32_t u = q[k], v = q[(k + 1) % 4], x = q[(k + 3) % 4], y = q[(k + 2) % 4];
      if (u > v) {
        std::swap(u, v);
        std::swap(x, y);
      }
      auto it =
          std::lower_bound(by_edge.begin(), by_edge.end(), std::make_pair(edge_key(u, v), -1));
      for (; it != by_edge.end() && it->first == edge_key(u, v); ++it) {
        if (it->second == o) continue;
        const QuadKey p = corners(it->second);
        const int iu = static_cast<int>(std::find(p.begin(), p.end(), u) - p.begin());
        const int iv = static_cast<int>(std::find(p.begin(), p.end(), v) - p.begin());
        // The corners next to u and v in the other face, away from the shared edge.
        const std::int32_t x2 = p[(iu + 1) % 4] == v ? p[(iu + 3) % 4] : p[(iu + 1) % 4];
        const std::int32_t y2 = p[(iv + 1) % 4] == u ? p[(iv + 3) % 4] : p[(iv + 1) % 4];
        if (x2 == x || y2 == y || x2 == y || y2 == x) continue;
        for (int flip = 0; flip < 2; ++flip) {
          Candidate c;
          c.kind = CellKind::Wedge6;
          c.nodes = flip ? std::array<std::int32_t, 8>{u, x2, x, v, y2, y, -1, -1}
                         : std::array<std::int32_t, 8>{u, x, x2, v, y, y2, -1, -1};
          c.tets.fill(-1);
          Vec3 w[6];
          for (int i = 0; i < 6; ++i) w[i] = X[c.nodes[i]];
          const double qual = min_scaled_jacobian(CellKind::Wedge6, w);
          if (!(qual > 0 && qual >= options.min_quality)) continue;
          c.quality = static_cast<float>(qual);
          cands.push_back(c);
        }
      }
    }
  }
  std::sort(cands.begin(), cands.end());
  cands.erase(
      std::unique(cands.begin(), cands.end(),
                  [](const Candidate& a, const Candidate& b) { return a.nodes == b.nodes; }),
      cands.end());
  struct Scored {
    int gain;
    std::size_t cand;
    bool operator<(const Scored& o) const { return gain != o.gain ? gain > o.gain : cand < o.cand; }
  };
  // Scores each fillable candidate against the current elements; 0 or less: not worth it.
  std::vector<std::int32_t> taken;  // pyramids the candidate takes
  auto score = [&](Candidate& c) {
    bool matches_nc = false;  // cheap test first: most candidates match no NC face
    const CellFaces qf = faces_of(c.kind);
    for (int f = 0; f < qf.count && !matches_nc; ++f) {
      if (qf.face[f].n != 4) continue;
      const std::int32_t o = owner_of(quad_key(c, f));
      matches_nc = o >= 0 && across[o].element == kTets;
    }
    if (!matches_nc) return 0;
    c.tets.fill(-1);
    if (!fills_element(topo, c, &soft, options.fill)) return 0;
    taken.clear();
    for (std::int32_t t : c.tets)
      if (t >= 0 && pyramid_of[t] >= 0 &&
          std::find(taken.begin(), taken.end(), pyramid_of[t]) == taken.end())
        taken.push_back(pyramid_of[t]);
    for (std::int32_t y : taken)  // both of its tets, or none
      for (int k = 0; k < 2; ++k)
        if (std::find(c.tets.begin(), c.tets.end(), elements[y].tets[k]) == c.tets.end()) return 0;
    int gain = 0, base_matched = 0;
    const CellFaces cf = faces_of(c.kind);
    for (int f = 0; f < cf.count; ++f) {
      if (cf.face[f].n != 4) continue;
      const QuadKey k = quad_key(c, f);
      const std::int32_t o = owner_of(k);
      if (o >= 0) {
        const Across a = across[o];
        if (a.element == kTets) {
          ++gain;
        } else if (a.element < 0 || elements[a.element].kind != CellKind::Pyramid5 ||
                   std::find(taken.begin(), taken.end(), a.element) == taken.end()) {
          return 0;  // matched by something it does not replace
        } else {
          ++base_matched;  // it replaces the pyramid there
        }
      } else if (!quad_on_surface(topo, c, f) && !pyramid_possible(topo, c, f, used, min_pyramid)) {
        --gain;
      }
    }
    gain -= static_cast<int>(taken.size()) - base_matched;
    return gain;
  };
  std::vector<Scored> order;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const int g = score(cands[i]);
    if (g > 0) order.push_back({g, i});
  }
  std::stable_sort(order.begin(), order.end());
  // A conflict needs two shared vertices: only the elements at a corner of a candidate kept
  // for placing go into the conformity index.
  std::vector<char> near(topo.num_vertices(), 0);
  for (const Scored& o : order)
    for (int k = 0; k < 6; ++k) near[cands[o.cand].nodes[k]] = 1;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const Candidate& e = elements[i];
    if (gone[i] || e.kind == CellKind::Pyramid5) continue;
    bool is_near = false;
    for (int k = 0; k < num_nodes(e.kind) && !is_near; ++k) is_near = near[e.nodes[k]];
    if (is_near) index.add(e);
  }
  std::size_t made = 0;
  std::vector<std::int32_t> fresh;  // new prisms and the elements they match
  for (const Scored& s : order) {
    Candidate c = cands[s.cand];
    if (score(c) < s.gain || index.conflicts(c)) continue;  // its neighbourhood changed
    for (std::int32_t y : taken) {
      gone[y] = 1;
      ++r.undone[static_cast<int>(CellKind::Pyramid5)];
      const Across a = across[6 * y];  // the face the pyramid rested on: now facing tets
      if (a.element >= 0) across[6 * a.element + a.face] = Across{};
    }
    const auto ci = static_cast<std::int32_t>(elements.size());
    elements.push_back(c);
    gone.push_back(0);
    across.resize(6 * elements.size());
    const CellFaces cf = faces_of(c.kind);
    for (int f = 0; f < cf.count; ++f) {
      if (cf.face[f].n != 4) continue;
      const std::int32_t o = owner_of(quad_key(c, f));
      if (o >= 0) {
        across[o] = {ci, static_cast<std::int8_t>(f)};
        across[6 * ci + f] = {o / 6, static_cast<std::int8_t>(o % 6)};
      } else if (quad_on_surface(topo, c, f)) {
        across[6 * ci + f].element = kSurface;
      }
      added.insert(std::lower_bound(added.begin(), added.end(), std::make_pair(quad_key(c, f), -1)),
                   {quad_key(c, f), 6 * ci + f});
    }
    for (std::int32_t t : c.tets)
      if (t >= 0) {
        used[t] = soft[t] = 1;
        pyramid_of[t] = -1;
      }
    index.add(c);
    ++made;
    fresh.push_back(ci);
    for (int f = 0; f < cf.count; ++f)
      if (across[6 * ci + f].element >= 0) fresh.push_back(across[6 * ci + f].element);
  }
  std::sort(fresh.begin(), fresh.end());
  fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
  for (std::int32_t i : fresh)
    if (!gone[i]) around.push_back(elements[i]);
  return made;
}

}  // namespace

std::size_t count_nc_faces(const TetTopology& topo, const std::vector<Candidate>& elements) {
  return count_nc(elements, faces_across(topo, elements), std::vector<char>(elements.size(), 0));
}

NcRepair undo_nonconformal_elements(const TetTopology& topo, std::vector<Candidate>& elements,
                                    std::vector<std::int32_t>& absorbed, std::vector<char>& used,
                                    double flat_sj, double keep_sj, double min_pyramid,
                                    int min_hex_gain, bool make_pyramids,
                                    const PrismOptions* prisms) {
  NcRepair r;
  std::vector<Across> across = faces_across(topo, elements);
  std::vector<char> gone(elements.size(), 0);
  r.nc_before = count_nc(elements, across, gone);
  // Absorbed slivers by their sorted corners: undoing an element frees those on its faces.
  const std::vector<KeyedTet> slivers = tets_by_corners(topo, absorbed);
  // 1: every tet it gives back, slivers on its faces included, is good enough to stand alone;
  // 0: not; -1: not known yet.
  std::vector<signed char> good(elements.size(), -1);
  auto gives_back_good_tets = [&](std::int32_t i) {
    if (good[i] >= 0) return good[i] == 1;
    const Candidate& e = elements[i];
    bool ok = true;
    for (std::int32_t t : e.tets) ok = ok && (t < 0 || tet_quality(topo, t) >= keep_sj);
    const CellFaces cf = faces_of(e.kind);
    for (int f = 0; f < cf.count && ok; ++f) {
      if (cf.face[f].n != 4) continue;
      const QuadKey k = quad_key(e, f);
      auto it = std::lower_bound(slivers.begin(), slivers.end(), std::make_pair(k, -1));
      for (; it != slivers.end() && it->first == k && ok; ++it)
        ok = tet_quality(topo, it->second) >= keep_sj;
    }
    good[i] = ok ? 1 : 0;
    return ok;
  };
  // The pyramids e's tets make on its partners' faces once e is undone (pyramid_behind), by
  // partner face: (e's face, the pyramid).
  std::vector<std::pair<int, Candidate>> behind;
  auto pyramids_behind = [&](std::int32_t i) {
    behind.clear();
    if (!make_pyramids) return;
    std::int32_t taken[8];
    int n = 0;
    const Candidate& e = elements[i];
    const CellFaces cf = faces_of(e.kind);
    for (int f = 0; f < cf.count; ++f) {
      const Across o = cf.face[f].n == 4 ? across[6 * i + f] : Across{};
      if (o.element < 0 || elements[o.element].kind == CellKind::Pyramid5) continue;
      Candidate c;
      if (!pyramid_behind(topo, e, f, elements[o.element], o.face, min_pyramid, taken, n, c))
        continue;
      taken[n++] = c.tets[0];
      taken[n++] = c.tets[1];
      behind.push_back({f, c});
    }
  };
  // Undoing changes its neighbours' counts: rounds, no two neighbours in one.
  for (;;) {
    std::vector<Undo> undo;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      if (gone[i]) continue;
      const CellFaces cf = faces_of(elements[i].kind);
      int gain = 0, nc = 0;
      bool ok = true;
      for (int f = 0; f < cf.count && ok; ++f) {
        if (cf.face[f].n != 4) continue;
        const Across& o = across[6 * i + f];
        if (o.element == kTets) {
          ++gain;  // an NC face goes
          ++nc;
        } else if (o.element >= 0) {
          if (elements[o.element].kind == CellKind::Pyramid5)
            ok = gives_back_good_tets(o.element);  // it goes too, leaving no NC face
          else
            --gain;  // the partner's face becomes NC, unless a pyramid of e's tets covers it
        }
      }
      const int need = elements[i].kind == CellKind::Hex8 ? min_hex_gain : 1;
      if (!ok || nc < need) continue;
      if (gain < need) {
        pyramids_behind(static_cast<std::int32_t>(i));
        gain += static_cast<int>(behind.size());
      }
      if (gain >= need && gives_back_good_tets(static_cast<std::int32_t>(i)))
        undo.push_back({gain, elements[i].quality, static_cast<std::int32_t>(i)});
    }
    if (undo.empty()) break;
    std::sort(undo.begin(), undo.end());
    std::vector<char> touched(elements.size(), 0);
    for (const Undo& u : undo) {
      if (touched[u.element]) continue;
      pyramids_behind(u.element);  // before across changes
      std::vector<std::int32_t> drop{u.element};
      touched[u.element] = 1;
      const CellFaces cf = faces_of(elements[u.element].kind);
      for (int f = 0; f < cf.count; ++f) {
        const std::int32_t o = cf.face[f].n == 4 ? across[6 * u.element + f].element : kTets;
        if (o < 0) continue;
        touched[o] = 1;
        if (elements[o].kind == CellKind::Pyramid5) drop.push_back(o);
      }
      // Partners' faces as they were, for the pyramids made on them below.
      std::vector<Across> partner;
      for (const auto& [f, c] : behind) partner.push_back(across[6 * u.element + f]);
      for (std::int32_t d : drop) {
        gone[d] = 1;
        ++r.undone[static_cast<int>(elements[d].kind)];
        for (std::int32_t t : elements[d].tets)
          if (t >= 0) used[t] = 0;
        const CellFaces df = faces_of(elements[d].kind);
        for (int f = 0; f < df.count; ++f) {
          const Across o = df.face[f].n == 4 ? across[6 * d + f] : Across{};
          if (o.element >= 0) across[6 * o.element + o.face] = Across{};  // now facing tets
        }
      }
      // The pyramids on the partners' faces, made now so the next rounds see those faces matched.
      for (std::size_t k = 0; k < behind.size(); ++k) {
        const Candidate& c = behind[k].second;
        const auto y = static_cast<std::int32_t>(elements.size());
        for (std::int32_t t : c.tets)
          if (t >= 0) used[t] = 1;
        elements.push_back(c);
        gone.push_back(0);
        good.push_back(-1);
        touched.push_back(1);
        across.resize(6 * elements.size());
        across[6 * y] = partner[k];  // the pyramid's base is its face 0
        across[6 * partner[k].element + partner[k].face] = {y, 0};
        ++r.pyramids_added;
      }
    }
  }
  std::vector<Candidate> around;
  if (prisms && make_pyramids)
    r.prisms_added =
        prisms_in_gaps(topo, elements, across, gone, used, *prisms, min_pyramid, r, around);
  r.nc_after = count_nc(elements, across, gone);
  std::size_t k = 0;
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (!gone[i]) elements[k++] = elements[i];
  elements.resize(k);
  release_orphan_slivers(topo, elements, absorbed, used, flat_sj);
  // Slivers between a new prism's face and the surface or a matched face belong to it, as after
  // the prism stage; flat ones on its faces against tets too, as after the pyramids.
  for (SliverPolicy p : {SliverPolicy::kSharedOrBoundary, SliverPolicy::kFlat}) {
    const auto more = absorb_face_slivers(topo, around, used, p, flat_sj);
    absorbed.insert(absorbed.end(), more.begin(), more.end());
  }
  if (!make_pyramids) return r;
  // The partners' faces left facing tets: a pyramid on one matches it (each sits on an NC face).
  std::vector<Candidate> pyramids = enumerate_pyramids(topo, elements, used, min_pyramid);
  const std::vector<Candidate> kept = place_pyramids(pyramids, used);
  r.pyramids_added += kept.size();
  r.nc_after -= kept.size();
  elements.insert(elements.end(), kept.begin(), kept.end());
  return r;
}

}  // namespace hexfem
