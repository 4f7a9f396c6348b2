#include "mesher/recombine_fill.hpp"

#include <algorithm>
#include <bit>
#include <limits>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

}  // namespace

int face_sliver_of(CellKind kind, const std::int32_t* nodes, const std::array<std::int32_t, 4>& T) {
  const CellFaces cf = faces_of(kind);
  for (int f = 0; f < cf.count; ++f) {
    const LocalFace& lf = cf.face[f];
    if (lf.n != 4) continue;
    int hits = 0;
    for (std::int32_t w : T)
      for (int i = 0; i < 4; ++i) hits += nodes[lf.v[i]] == w;
    if (hits == 4) return f;
  }
  return -1;
}

bool is_face_sliver(CellKind kind, const std::int32_t* nodes,
                    const std::array<std::int32_t, 4>& T) {
  return face_sliver_of(kind, nodes, T) >= 0;
}

bool fills_element(const TetTopology& topo, Candidate& c, const std::vector<char>* used,
                   const FillRules& rules) {
  const TetMesh& m = topo.mesh();
  const int nn = num_nodes(c.kind);
  const std::int32_t* nodes = c.nodes.data();
  // Local index of a node, or -1: compared with all eight slots at once (unused slots are -1),
  // no memory lookup.
  auto local = [&](std::int32_t v) -> int {
    unsigned hit = 0;
    for (int i = 0; i < 8; ++i) hit |= static_cast<unsigned>(nodes[i] == v) << i;
    return hit ? std::countr_zero(hit) : -1;
  };
  // Quad faces as masks of local corners.
  const CellFaces cf = faces_of(c.kind);
  unsigned face_mask[6];
  for (int f = 0; f < cf.count; ++f) {
    face_mask[f] = 0;
    for (int i = 0; i < cf.face[f].n; ++i) face_mask[f] |= 1u << cf.face[f].v[i];
  }
  // The tets with all vertices among the nodes: each is listed once, by its lowest vertex, which
  // is at most the fourth highest node.
  std::array<std::int32_t, 8> sorted_ids;  // unused slots sort first
  for (int i = 0; i < 8; ++i)
    sorted_ids[i] = i < nn ? nodes[i] : std::numeric_limits<std::int32_t>::min();
  std::sort(sorted_ids.begin(), sorted_ids.end());
  const std::int32_t lowest_max = sorted_ids[8 - 4];
  std::int32_t ts[8];
  unsigned tmask[8];
  int low[8];  // lowest local corner of each tet: they are listed by it, then by index
  int n = 0;
  for (int i = 0; i < nn; ++i) {
    if (nodes[i] > lowest_max) continue;
    for (auto u = topo.upper_begin(nodes[i]); u != topo.upper_end(nodes[i]); ++u) {
      unsigned mask = 1u << i;
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k) {
        const int l = local(u->v[k]);
        inside = l >= 0;
        if (inside) mask |= 1u << l;
      }
      if (!inside) continue;
      // A flat tet spanning the four corners of a quad face lies on the face, between its two
      // diagonals (a sliver of a near-planar face): not part of the element.
      bool sliver = false;
      for (int f = 0; f < cf.count; ++f) sliver = sliver || mask == face_mask[f];
      if (sliver) continue;
      if (used && (*used)[u->tet]) return false;  // (the check below, early: most fail here)
      if (n == 7) return false;
      int j = n++;
      const int lo = std::countr_zero(mask);
      for (; j > 0 && (low[j - 1] > lo || (low[j - 1] == lo && ts[j - 1] > u->tet)); --j) {
        ts[j] = ts[j - 1];
        tmask[j] = tmask[j - 1];
        low[j] = low[j - 1];
      }
      ts[j] = u->tet;
      tmask[j] = mask;
      low[j] = lo;
    }
  }
  const int min_tets = c.kind == CellKind::Hex8 ? 5 : c.kind == CellKind::Wedge6 ? 3 : 2;
  if (n < min_tets) return false;
  const std::int32_t solid = m.tet_solid[ts[0]];
  for (int i = 0; i < n; ++i) {
    if (m.tet_solid[ts[i]] != solid) return false;
    if (used && (*used)[ts[i]]) return false;
  }
  // Faces used by exactly one tet bound the union; each must lie in a face of the element.
  unsigned tri[28];
  int nt = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 8; ++k)
      if (tmask[i] & (1u << k)) tri[nt++] = tmask[i] & ~(1u << k);
  std::sort(tri, tri + nt);
  unsigned bnd[28];
  int nb = 0;
  for (int i = 0; i < nt;) {
    int j = i + 1;
    while (j < nt && tri[j] == tri[i]) ++j;
    if (j - i > 2) return false;
    if (j - i == 1) bnd[nb++] = tri[i];
    i = j;
  }
  int want = 0;
  for (int f = 0; f < cf.count; ++f) want += cf.face[f].n == 4 ? 2 : 1;
  if (nb != want) return false;
  const auto num_surface = static_cast<std::int32_t>(topo.num_surface_nodes());
  for (int f = 0; f < cf.count; ++f) {
    const LocalFace& lf = cf.face[f];
    unsigned in[2];
    int covered = 0;
    for (int b = 0; b < nb; ++b)
      if ((bnd[b] & ~face_mask[f]) == 0) {
        if (covered < 2) in[covered] = bnd[b];
        ++covered;
      }
    if (covered != (lf.n == 4 ? 2 : 1)) return false;
    if (lf.n == 3) continue;
    // The two triangles split the quad along a diagonal: the corners they miss are opposite.
    const unsigned miss0 = face_mask[f] & ~in[0], miss1 = face_mask[f] & ~in[1];
    if (((miss0 | miss1) != ((1u << lf.v[0]) | (1u << lf.v[2]))) &&
        ((miss0 | miss1) != ((1u << lf.v[1]) | (1u << lf.v[3]))))
      return false;
    // A quad face lies wholly inside, or wholly on one CAD face (never across a CAD edge).
    int surface_corners = 0;  // surface nodes come first in the tet mesh
    for (int i = 0; i < 4; ++i) surface_corners += nodes[lf.v[i]] < num_surface;
    if (surface_corners < 3) continue;
    std::int32_t st[2];
    for (int k = 0; k < 2; ++k) {
      std::int32_t v[3];
      int nv = 0;
      for (int i = 0; i < 8; ++i)
        if (in[k] & (1u << i)) v[nv++] = nodes[i];
      st[k] = topo.surface_triangle(v[0], v[1], v[2]);
    }
    if ((st[0] < 0) != (st[1] < 0)) return false;
    if (st[0] >= 0 && topo.cad_face(st[0]) != topo.cad_face(st[1])) return false;
    if (st[0] >= 0) continue;
    // An interior quad with one surface triangle on three of its corners (split along the
    // other diagonal; the fourth corner may be inside) would be half interior, half boundary:
    // neither matched by the cells across it nor a boundary face. Both is fine: the flat
    // sliver between becomes part of the element and the quad a boundary face
    // (absorb_face_slivers).
    const std::int32_t* q = nodes;
    const int* v = lf.v.data();
    const bool d02 = (miss0 | miss1) == ((1u << v[1]) | (1u << v[3]));  // tets split along 0-2
    const std::int32_t o1 = d02 ? topo.surface_triangle(q[v[0]], q[v[1]], q[v[3]])
                                : topo.surface_triangle(q[v[0]], q[v[1]], q[v[2]]);
    const std::int32_t o2 = d02 ? topo.surface_triangle(q[v[1]], q[v[2]], q[v[3]])
                                : topo.surface_triangle(q[v[0]], q[v[2]], q[v[3]]);
    if ((o1 < 0) != (o2 < 0)) return false;
  }
  double tet_vol = 0;
  for (int i = 0; i < n; ++i) tet_vol += topo.tet_volume(ts[i]);
  Vec3 x[8];
  for (int i = 0; i < nn; ++i) x[i] = m.nodes[nodes[i]];
  // Each non-planar quad face can leave half the tet spanned by its corners as a gap (or
  // overlap) against whatever lies across it; bound the sum against the element's volume.
  double twist = 0;
  for (int f = 0; f < cf.count; ++f) {
    if (cf.face[f].n != 4) continue;
    const auto& q = cf.face[f].v;
    const Vec3 t[4] = {x[q[0]], x[q[1]], x[q[2]], x[q[3]]};
    twist += 0.5 * std::abs(volume(CellKind::Tet4, t));
  }
  if (!(twist <= rules.max_face_twist * tet_vol)) return false;
  const double v = volume(c.kind, x);
  if (!(std::abs(v - tet_vol) <= rules.max_volume_gap * tet_vol)) return false;
  for (int i = 0; i < 7; ++i) c.tets[i] = i < n ? ts[i] : -1;
  return true;
}

int quad_diagonal(const TetTopology& topo, const Candidate& c, int local_face) {
  // The 0-2 diagonal is used iff some tet of the element contains both of its ends.
  const LocalFace lf = faces_of(c.kind).face[local_face];
  const std::int32_t a = c.nodes[lf.v[0]], b = c.nodes[lf.v[2]];
  for (std::int32_t t : c.tets) {
    if (t < 0) break;
    const auto& T = topo.mesh().tets[t];
    const bool ha = T[0] == a || T[1] == a || T[2] == a || T[3] == a;
    const bool hb = T[0] == b || T[1] == b || T[2] == b || T[3] == b;
    if (ha && hb) return 0;
  }
  return 1;
}

std::uint32_t next_near_epoch(FillScratch& scratch) {
  if (++scratch.near_epoch == 0) {  // wrapped: forget every old mark
    std::fill(scratch.near.begin(), scratch.near.end(), 0);
    scratch.near_epoch = 1;
  }
  return scratch.near_epoch;
}

void quads_at(const TetTopology& topo, std::int32_t v, double min_sin, FillScratch& scratch,
              const std::vector<char>* used) {
  auto taken = [&](std::int32_t t) { return used && (*used)[t]; };
  scratch.quads.clear();
  scratch.keys.clear();
  if (used && std::all_of(topo.star_begin(v), topo.star_end(v), taken)) {
    scratch.num_up = 0;  // no free tet at v: no quad of free tets
    return;
  }
  const TetMesh& m = topo.mesh();
  const Vec3& pv = m.nodes[v];
  auto corner_ok = [&](std::int32_t a, std::int32_t b) {
    const Vec3 ea = sub(m.nodes[a], pv), eb = sub(m.nodes[b], pv);
    const Vec3 c{ea[1] * eb[2] - ea[2] * eb[1], ea[2] * eb[0] - ea[0] * eb[2],
                 ea[0] * eb[1] - ea[1] * eb[0]};
    const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    const double aa = ea[0] * ea[0] + ea[1] * ea[1] + ea[2] * ea[2];
    const double bb = eb[0] * eb[0] + eb[1] * eb[1] + eb[2] * eb[2];
    return cc >= min_sin * min_sin * aa * bb;
  };
  // The corners a, b of the quads are v's neighbours above v: numbered 0..n-1 in increasing
  // order, so that keys packed from those numbers sort like the vertex ids.
  const std::int32_t* up = std::upper_bound(topo.neighbours_begin(v), topo.neighbours_end(v), v);
  const auto n_up = static_cast<std::size_t>(topo.neighbours_end(v) - up);
  if (n_up >= (1u << 16)) throw Error("a vertex of the tet mesh has over 65535 neighbours");
  scratch.up = up;
  scratch.num_up = n_up;
  if (scratch.local.size() != m.nodes.size()) scratch.local.assign(m.nodes.size(), 0);
  const std::uint64_t stamp = ++scratch.local_epoch << 32;
  for (std::size_t i = 0; i < n_up; ++i) scratch.local[up[i]] = stamp | i;
  auto local = [&](std::int32_t w) { return static_cast<std::uint32_t>(scratch.local[w]); };
  // Ordered pairs (a, b) of vertices above v sharing a tet with v (the edges of v's link, both
  // ways round), sorted, as (local a) << 16 | local b.
  auto& pairs = scratch.pairs;
  pairs.clear();
  for (auto it = topo.star_begin(v); it != topo.star_end(v); ++it) {
    if (taken(*it)) continue;
    std::uint32_t lu[3];
    int n = 0;
    for (std::int32_t w : m.tets[*it])
      if (w > v) lu[n++] = local(w);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (i != j) pairs.push_back(lu[i] << 16 | lu[j]);
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  // Quads (a, b, x) as (local a) << 48 | (local b) << 32 | x.
  auto& keys = scratch.keys;
  keys.clear();
  auto key = [](std::uint64_t la, std::uint64_t lb, std::int32_t x) {
    return la << 48 | lb << 32 | static_cast<std::uint32_t>(x);
  };
  if (scratch.near.size() != m.nodes.size()) scratch.near.assign(m.nodes.size(), 0);
  for (std::size_t i = 0; i < pairs.size();) {
    const std::uint32_t la = pairs[i] >> 16;
    const std::int32_t a = up[la];
    std::size_t end = i;
    while (end < pairs.size() && pairs[end] >> 16 == la) ++end;
    // (1) Split along a-b: triangle (v, a, b) and (a, x, b) of any tet around edge a-b. The
    // partners b > a that make a good corner are marked; each tet around a holding one of them
    // is a tet around that edge (one pass over a's star for all of a's partners).
    const std::uint32_t epoch = next_near_epoch(scratch);
    bool any = false;
    for (std::size_t k = i; k < end; ++k) {
      const std::int32_t b = up[pairs[k] & 0xffff];
      if (b > a && corner_ok(a, b)) {
        scratch.near[b] = epoch;
        any = true;
      }
    }
    // The star's tets lie all over memory: asked for all at once, not one miss after another.
    if (any)
      for (auto s = topo.star_begin(a); s != topo.star_end(a); ++s) __builtin_prefetch(&m.tets[*s]);
    if (any)
      for (auto s = topo.star_begin(a); s != topo.star_end(a); ++s) {
        if (taken(*s)) continue;
        const auto& T = m.tets[*s];
        for (std::int32_t b : T) {
          if (scratch.near[b] != epoch) continue;
          for (std::int32_t x : T)
            if (x != a && x != b && x > v) keys.push_back(key(la, local(b), x));
        }
      }
    // (2) Split along v-x with x = a: triangles (v, b, a) and (v, a, c), b and c around edge
    // v-a (a's partners, sorted).
    for (std::size_t j = i; j < end; ++j)
      for (std::size_t k = j + 1; k < end; ++k) {
        const std::uint32_t lb = pairs[j] & 0xffff, lc = pairs[k] & 0xffff;
        if (corner_ok(up[lb], up[lc])) keys.push_back(key(lb, lc, a));
      }
    i = end;
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  auto& q = scratch.quads;
  q.resize(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i)
    q[i] = {up[keys[i] >> 48], up[keys[i] >> 32 & 0xffff], static_cast<std::int32_t>(keys[i])};
}

std::pair<const CornerQuad*, const CornerQuad*> quads_between(const FillScratch& scratch,
                                                              std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  const CornerQuad* lo = scratch.quads.data();
  const CornerQuad* hi = lo + scratch.quads.size();
  const CornerQuad key_lo{a, b, std::numeric_limits<std::int32_t>::min()};
  const CornerQuad key_hi{a, b, std::numeric_limits<std::int32_t>::max()};
  return {std::lower_bound(lo, hi, key_lo), std::upper_bound(lo, hi, key_hi)};
}

QuadKey quad_corners(const Candidate& e, int local_face) {
  const LocalFace lf = faces_of(e.kind).face[local_face];
  QuadKey q;
  for (int i = 0; i < 4; ++i) q[i] = e.nodes[lf.v[i]];
  return q;
}

QuadKey quad_key(const Candidate& e, int local_face) {
  // Five compare-exchanges (a sorting network) instead of std::sort's loop: called for every
  // quad face of every element, several times per stage.
  QuadKey k = quad_corners(e, local_face);
  auto order = [&](int i, int j) {
    const std::int32_t lo = std::min(k[i], k[j]), hi = std::max(k[i], k[j]);
    k[i] = lo;
    k[j] = hi;
  };
  order(0, 1);
  order(2, 3);
  order(0, 2);
  order(1, 3);
  order(1, 2);
  return k;
}

}  // namespace hexfem
