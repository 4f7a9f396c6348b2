#include "mesher/recombine_prism_pyramid.hpp"

#include <algorithm>
#include <cmath>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

// Wedge corners (Gmsh order): 0:(1,2,3) 1:(2,0,4) 2:(0,1,5) 3:(5,4,0) 4:(3,5,1) 5:(4,3,2).
// From lowest vertex v = p0, the labelling is unique (p3 is v's edge to the other triangle,
// p1/p2 ordered by orientation), so each prism is found once.
void prisms_from(const TetTopology& topo, const std::vector<char>& used, std::int32_t v,
                 double qmin, FillScratch& scratch, std::vector<Candidate>& out) {
  const auto& X = topo.mesh().nodes;
  // The wedge's ideal corner (60 degrees) has raw value sqrt(3)/2; quality.hpp scales it to 1.
  const double raw_min = qmin * std::sqrt(3.0) / 2.0;
  auto ok = [&](std::int32_t o, std::int32_t a, std::int32_t b, std::int32_t c) {
    return corner_at_least(X[o], X[a], X[b], X[c], raw_min);
  };
  // A prism's quad faces are faces of its tets, which must be free: quads of free tets only.
  quads_at(topo, v, raw_min, scratch, &used);
  if (scratch.quads.empty()) return;  // a prism at v has two quad faces at v
  // Partners of each vertex through a quad at v (both directions), sorted.
  auto& partner = scratch.prism_partners;
  partner.clear();
  for (const CornerQuad& q : scratch.quads) {
    partner.emplace_back(q.a, q.b);
    partner.emplace_back(q.b, q.a);
  }
  std::sort(partner.begin(), partner.end());
  partner.erase(std::unique(partner.begin(), partner.end()), partner.end());
  auto partners = [&](std::int32_t u) {
    return std::equal_range(partner.begin(), partner.end(),
                            std::pair<std::int32_t, std::int32_t>{u, 0},
                            [](const auto& x, const auto& y) { return x.first < y.first; });
  };
  // Bottom triangles (v, p1, p2): faces of free tets around v.
  auto& tris = scratch.prism_bottoms;
  tris.clear();
  for (auto it = topo.star_begin(v); it != topo.star_end(v); ++it) {
    if (used[*it]) continue;
    std::int32_t o[3], n = 0;
    for (std::int32_t w : topo.mesh().tets[*it])
      if (w != v) o[n++] = w;
    for (int i = 0; i < 3; ++i) {
      const std::int32_t a = std::min(o[i], o[(i + 1) % 3]), b = std::max(o[i], o[(i + 1) % 3]);
      if (a > v) tris.emplace_back(a, b);
    }
  }
  std::sort(tris.begin(), tris.end());
  tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
  for (const auto& [a, b] : tris) {
    const auto ra = partners(a), rb = partners(b);
    for (auto ia = ra.first; ia != ra.second; ++ia) {
      const std::int32_t p3 = ia->second;
      if (p3 == b ||
          !std::binary_search(rb.first, rb.second, std::pair<std::int32_t, std::int32_t>{b, p3}))
        continue;
      std::int32_t p1 = a, p2 = b;
      if (!ok(v, p1, p2, p3)) {
        std::swap(p1, p2);
        if (!ok(v, p1, p2, p3)) continue;
      }
      const auto c4 = quads_between(scratch, p1, p3);
      const auto c5 = quads_between(scratch, p2, p3);
      for (const CornerQuad* q4 = c4.first; q4 != c4.second; ++q4) {
        const std::int32_t p4 = q4->x;
        if (p4 == p2 || !ok(p1, p2, v, p4)) continue;
        for (const CornerQuad* q5 = c5.first; q5 != c5.second; ++q5) {
          const std::int32_t p5 = q5->x;
          if (p5 == p1 || p5 == p4 || !topo.adjacent(p4, p5)) continue;
          if (!topo.adjacent(p1, p5) && !topo.adjacent(p2, p4)) continue;
          if (!ok(p2, v, p1, p5) || !ok(p3, p5, p4, v) || !ok(p4, p3, p5, p1) ||
              !ok(p5, p4, p3, p2))
            continue;
          Candidate c;
          c.kind = CellKind::Wedge6;
          c.nodes = {v, p1, p2, p3, p4, p5, -1, -1};
          c.tets.fill(-1);  // checked by place_greedily
          Vec3 x[6];
          for (int k = 0; k < 6; ++k) x[k] = X[c.nodes[k]];
          c.quality = static_cast<float>(min_scaled_jacobian(CellKind::Wedge6, x));
          out.push_back(c);
        }
      }
    }
  }
}

// The tet other than those of `own` and `skip` that has triangle (a, b, c) as a face, or -1.
std::int32_t tet_across(const TetTopology& topo, const Candidate& own, std::int32_t skip,
                        std::int32_t a, std::int32_t b, std::int32_t c) {
  for (auto it = topo.star_begin(a); it != topo.star_end(a); ++it) {
    const std::int32_t t = *it;
    if (t == skip || std::find(own.tets.begin(), own.tets.end(), t) != own.tets.end()) continue;
    const auto& T = topo.mesh().tets[t];
    const bool hb = T[0] == b || T[1] == b || T[2] == b || T[3] == b;
    const bool hc = T[0] == c || T[1] == c || T[2] == c || T[3] == c;
    if (hb && hc) return t;
  }
  return -1;
}

std::int32_t apex_of(const TetTopology& topo, std::int32_t t, std::int32_t a, std::int32_t b,
                     std::int32_t c) {
  for (std::int32_t w : topo.mesh().tets[t])
    if (w != a && w != b && w != c) return w;
  return -1;
}

}  // namespace

std::vector<Candidate> enumerate_prisms(const RecombineState& state) {
  return collect_candidates(static_cast<std::int32_t>(state.topo.num_vertices()),
                            [&](std::int32_t v, FillScratch& scratch, std::vector<Candidate>& out) {
                              prisms_from(state.topo, state.used, v, state.limits.min_quality,
                                          scratch, out);
                            });
}

std::vector<Candidate> enumerate_pyramids(const RecombineState& state) {
  const TetTopology& topo = state.topo;
  const std::vector<Candidate>& elements = state.elements;
  const std::vector<char>& used = state.used;
  const double min_quality = state.limits.min_pyramid_quality;
  // Quad faces used by two elements are conformal already.
  const QuadFaces quads(elements, topo.num_vertices());
  std::vector<Candidate> out;
  const auto& X = topo.mesh().nodes;
  const auto n = static_cast<std::ptrdiff_t>(elements.size());
#pragma omp parallel
  {
    std::vector<Candidate> local;
#pragma omp for schedule(static, 1024) nowait
    for (std::ptrdiff_t ei = 0; ei < n; ++ei) {
      const Candidate& e = elements[ei];
      const CellFaces cf = faces_of(e.kind);
      for (int f = 0; f < cf.count; ++f) {
        const LocalFace& lf = cf.face[f];
        if (lf.n != 4) continue;
        const QuadKey q = quad_corners(e, f);
        if (quads.shared(6 * ei + f)) continue;
        // The two triangles of the face, split along the diagonal the element's tets use; past a
        // flat sliver on the face, along the other diagonal.
        std::array<std::int32_t, 3> t1, t2;
        auto split = [&](int diagonal) {
          if (diagonal == 0) {
            t1 = {q[0], q[1], q[2]};
            t2 = {q[0], q[2], q[3]};
          } else {
            t1 = {q[0], q[1], q[3]};
            t2 = {q[1], q[2], q[3]};
          }
        };
        const int diagonal = quad_diagonal(topo, e, f);
        split(diagonal);
        if (topo.surface_triangle(t1[0], t1[1], t1[2]) >= 0) continue;  // a boundary quad
        std::int32_t a = tet_across(topo, e, -1, t1[0], t1[1], t1[2]);
        std::int32_t b = tet_across(topo, e, -1, t2[0], t2[1], t2[2]);
        std::int32_t sliver = -1;
        if (a >= 0 && a == b && face_sliver_of(e.kind, e.nodes.data(), topo.mesh().tets[a]) == f) {
          sliver = a;  // the pyramid takes it: its bilinear base cuts it where the face does
          if (used[sliver]) continue;
          split(1 - diagonal);
          a = tet_across(topo, e, sliver, t1[0], t1[1], t1[2]);
          b = tet_across(topo, e, sliver, t2[0], t2[1], t2[2]);
        }
        if (a < 0 || b < 0 || a == b || used[a] || used[b]) continue;
        if (topo.mesh().tet_solid[a] != topo.mesh().tet_solid[b]) continue;
        const std::int32_t apex = apex_of(topo, a, t1[0], t1[1], t1[2]);
        if (apex != apex_of(topo, b, t2[0], t2[1], t2[2])) continue;
        // Base in the element's outward order: the pyramid's own base face (0,3,2,1) then points
        // back into the element, i.e. out of the pyramid.
        Candidate c;
        c.kind = CellKind::Pyramid5;
        c.nodes = {q[0], q[1], q[2], q[3], apex, -1, -1, -1};
        c.tets = {std::min(a, b), std::max(a, b), sliver, -1, -1, -1, -1};
        Vec3 x[5];
        for (int i = 0; i < 5; ++i) x[i] = X[c.nodes[i]];
        const double qual = min_scaled_jacobian(CellKind::Pyramid5, x);
        if (!(qual > 0 && qual >= min_quality)) continue;
        c.quality = static_cast<float>(qual);
        local.push_back(c);
      }
    }
#pragma omp critical
    out.insert(out.end(), local.begin(), local.end());
  }
  // Distinct candidates, totally ordered: the order does not depend on the threads.
  std::sort(out.begin(), out.end());
  return out;
}

std::size_t place_pyramids(RecombineState& state, std::vector<Candidate>& cands) {
  std::sort(cands.begin(), cands.end());
  std::size_t kept = 0;
  for (const Candidate& c : cands) {
    bool free = true;
    for (std::int32_t t : c.tets) free = free && (t < 0 || !state.used[t]);
    if (!free) continue;
    state.place(c);
    ++kept;
  }
  state.debug_verify();
  return kept;
}

// The free tets with a min scaled Jacobian below `bound`, as (quality, tet) in tet order.
static std::vector<std::pair<double, std::int32_t>> free_tets_below(const RecombineState& state,
                                                                    double bound) {
  std::vector<std::pair<double, std::int32_t>> found;
  for (std::size_t s = 0; s < state.used.size(); ++s) {
    if (state.used[s]) continue;
    const double q = tet_quality(state.topo, static_cast<std::int32_t>(s));
    if (q < bound) found.emplace_back(q, static_cast<std::int32_t>(s));
  }
  return found;
}

std::size_t merge_slivers_into_pyramids(RecombineState& state) {
  const TetTopology& topo = state.topo;
  const std::vector<char>& used = state.used;
  const double min_pyramid = state.limits.min_pyramid_quality;
  const TetMesh& m = topo.mesh();
  // Flattest first: a flat tet gets the tets around it before a mere sliver takes them.
  std::vector<std::pair<double, std::int32_t>> by_quality =
      free_tets_below(state, state.limits.sliver_quality);
  if (by_quality.empty()) return 0;
  std::sort(by_quality.begin(), by_quality.end());
  std::vector<std::int32_t> slivers;
  for (const auto& [q, t] : by_quality) slivers.push_back(t);
  // Three corners of each quad face -> its fourth corner (the first quad's, in the order they
  // are added). Only triples of a sliver's vertices are ever looked up: the others are skipped.
  OpenHashSet<TriKey, TriKeyHash> wanted(4 * slivers.size());
  for (const std::int32_t t : slivers)
    for (int skip = 0; skip < 4; ++skip)
      wanted.insert(
          tri_key(m.tets[t][(skip + 1) % 4], m.tets[t][(skip + 2) % 4], m.tets[t][(skip + 3) % 4]));
  TriKeyMap quad_of_triple(4 * slivers.size());
  auto add_quad = [&](const std::array<std::int32_t, 4>& q) {
    for (int skip = 0; skip < 4; ++skip) {
      const TriKey k = tri_key(q[(skip + 1) % 4], q[(skip + 2) % 4], q[(skip + 3) % 4]);
      if (wanted.contains(k)) quad_of_triple.emplace(k, q[skip]);
    }
  };
  auto clashes = [&](const std::array<std::int32_t, 4>& q) {
    for (int skip = 0; skip < 4; ++skip) {
      const std::int32_t* fourth =
          quad_of_triple.find(tri_key(q[(skip + 1) % 4], q[(skip + 2) % 4], q[(skip + 3) % 4]));
      if (fourth && *fourth != q[skip]) return true;
    }
    return false;
  };
  // A quad can add a wanted triple only with three corners on slivers: the others are skipped
  // before any hashing (they are nearly all of them).
  std::vector<char> on_sliver(topo.num_vertices(), 0);
  for (const std::int32_t t : slivers)
    for (const std::int32_t v : m.tets[t]) on_sliver[v] = 1;
  for (const Candidate& e : state.elements) {
    const CellFaces& cf = faces_of(e.kind);
    for (int f = 0; f < cf.count; ++f) {
      if (cf.face[f].n != 4) continue;
      const std::array<std::int32_t, 4> q{e.nodes[cf.face[f].v[0]], e.nodes[cf.face[f].v[1]],
                                          e.nodes[cf.face[f].v[2]], e.nodes[cf.face[f].v[3]]};
      if (on_sliver[q[0]] + on_sliver[q[1]] + on_sliver[q[2]] + on_sliver[q[3]] >= 3) add_quad(q);
    }
  }
  std::size_t made = 0;
  for (const std::int32_t t : slivers) {
    if (used[t]) continue;  // taken by a pyramid made for an earlier sliver
    const auto& T = m.tets[t];
    Candidate best;
    best.quality = -1;
    // The quad's diagonals (T[0], T[i]) and the other two; then either diagonal's side.
    for (int i = 1; i < 4; ++i) {
      const std::int32_t a = T[0], c = T[i];
      std::int32_t bd[2], n = 0;
      for (int k = 1; k < 4; ++k)
        if (k != i) bd[n++] = T[k];
      const std::array<std::int32_t, 4> quad{a, bd[0], c, bd[1]};
      if (clashes(quad)) continue;
      for (int side = 0; side < 2; ++side) {
        // Triangles of the quad split along the diagonal (q0, q2) of this side.
        const std::int32_t q0 = quad[side], q1 = quad[side + 1], q2 = quad[side + 2],
                           q3 = quad[(side + 3) % 4];
        // The far side: both surface triangles (the base becomes a boundary quad) or neither
        // (an interior quad against cells); half and half would be neither.
        if ((topo.surface_triangle(q0, q1, q3) < 0) != (topo.surface_triangle(q1, q2, q3) < 0))
          continue;
        const std::int32_t u = topo.tet_across(t, q0, q1, q2), w = topo.tet_across(t, q0, q2, q3);
        if (u < 0 || w < 0 || u == w || used[u] || used[w]) continue;
        if (m.tet_solid[u] != m.tet_solid[t] || m.tet_solid[w] != m.tet_solid[t]) continue;
        const std::int32_t apex = apex_of(topo, u, q0, q1, q2);
        if (apex != apex_of(topo, w, q0, q2, q3)) continue;
        for (int dir = 0; dir < 2; ++dir) {
          Candidate pyr;
          pyr.kind = CellKind::Pyramid5;
          pyr.nodes = {
              quad[0], dir ? quad[3] : quad[1], quad[2], dir ? quad[1] : quad[3], apex, -1, -1, -1};
          pyr.tets = {std::min(u, w), std::max(u, w), t, -1, -1, -1, -1};
          Vec3 x[5];
          for (int k = 0; k < 5; ++k) x[k] = m.nodes[pyr.nodes[k]];
          pyr.quality = static_cast<float>(min_scaled_jacobian(CellKind::Pyramid5, x));
          if (pyr.quality >= min_pyramid && pyr.quality > best.quality) best = pyr;
        }
      }
    }
    if (best.quality < 0) continue;
    add_quad({best.nodes[0], best.nodes[1], best.nodes[2], best.nodes[3]});
    state.place(best);
    ++made;
  }
  state.debug_verify();
  return made;
}

std::size_t dissolve_pyramids_next_to_slivers(RecombineState& state) {
  const TetTopology& topo = state.topo;
  const std::vector<Candidate>& elements = state.elements;
  const std::vector<std::int32_t> owner = state.element_of_tets();
  const TetMesh& m = topo.mesh();
  const double element_sj = state.limits.keep_tet_quality;
  std::vector<char> dissolve(elements.size(), 0);
  for (const auto& slivers : free_tets_below(state, state.limits.sliver_quality)) {
    const double q = slivers.first;
    const std::int32_t t = slivers.second;
    const auto& T = m.tets[t];
    auto mark = [&](std::int32_t other) {
      const std::int32_t e = owner[other];
      if (elements[e].kind == CellKind::Pyramid5 || q < element_sj) dissolve[e] = 1;
    };
    // Tets sharing a face with t (three of their vertices are t's); for a flat t, every tet
    // around its edges (two shared vertices), since a flip removes a whole edge shell.
    const int need = q < element_sj ? 2 : 3;
    for (int i = 0; i < 4; ++i)
      for (auto it = topo.star_begin(T[i]); it != topo.star_end(T[i]); ++it) {
        if (*it == t || owner[*it] < 0) continue;
        int shared = 0;
        for (std::int32_t w : m.tets[*it])
          shared += w == T[0] || w == T[1] || w == T[2] || w == T[3];
        if (shared >= need) mark(*it);
      }
  }
  const auto gone = static_cast<std::size_t>(std::count(dissolve.begin(), dissolve.end(), 1));
  state.remove(dissolve);
  state.debug_verify();
  return gone;
}

}  // namespace hexfem
