#include "mesher/recombine_common.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

TriKey tri_key(std::int32_t a, std::int32_t b, std::int32_t c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {{a, b, c}};
}

namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

}  // namespace

TetTopology::TetTopology(const TetMesh& tets, const SurfaceMesh& surface) : mesh_(tets) {
  const std::size_t nv = tets.nodes.size(), nt = tets.tets.size();
  // Star: counting sort by vertex keeps tets in increasing order around each vertex.
  star_off_.assign(nv + 1, 0);
  for (const auto& T : tets.tets)
    for (std::int32_t v : T) ++star_off_[v + 1];
  for (std::size_t v = 0; v < nv; ++v) star_off_[v + 1] += star_off_[v];
  star_.resize(star_off_[nv]);
  {
    std::vector<std::int32_t> fill(star_off_.begin(), star_off_.end() - 1);
    for (std::size_t t = 0; t < nt; ++t)
      for (std::int32_t v : tets.tets[t]) star_[fill[v]++] = static_cast<std::int32_t>(t);
  }
  upper_off_.assign(nv + 1, 0);
  for (const auto& T : tets.tets) ++upper_off_[*std::min_element(T.begin(), T.end()) + 1];
  for (std::size_t v = 0; v < nv; ++v) upper_off_[v + 1] += upper_off_[v];
  upper_.resize(nt);
  {
    std::vector<std::int32_t> fill(upper_off_.begin(), upper_off_.end() - 1);
    for (std::size_t t = 0; t < nt; ++t) {
      const auto& T = tets.tets[t];
      const int lo = static_cast<int>(std::min_element(T.begin(), T.end()) - T.begin());
      UpperTet& u = upper_[fill[T[lo]]++];
      u.tet = static_cast<std::int32_t>(t);
      for (int k = 1; k < 4; ++k) u.v[k - 1] = T[(lo + k) % 4];
    }
  }
  // Neighbours: the other vertices of the star, sorted and unique; each vertex's list is made in
  // its slot of 3 x its star (on all threads), then the slots are packed.
  std::vector<std::int32_t> wide(3 * star_.size());
  std::vector<std::int32_t> count(nv);
  const auto num_v = static_cast<std::ptrdiff_t>(nv);
#pragma omp parallel for schedule(dynamic, 1024)
  for (std::ptrdiff_t v = 0; v < num_v; ++v) {
    std::int32_t* begin = &wide[3 * static_cast<std::size_t>(star_off_[v])];
    std::int32_t* end = begin;
    for (auto it = star_begin(v); it != star_end(v); ++it)
      for (std::int32_t w : tets.tets[*it])
        if (w != v) *end++ = w;
    std::sort(begin, end);
    count[v] = static_cast<std::int32_t>(std::unique(begin, end) - begin);
  }
  adj_off_.assign(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) adj_off_[v + 1] = adj_off_[v] + count[v];
  adj_.resize(adj_off_[nv]);
  for (std::size_t v = 0; v < nv; ++v)
    std::copy_n(&wide[3 * static_cast<std::size_t>(star_off_[v])], count[v], &adj_[adj_off_[v]]);
  const MixedMesh& sm = surface.mesh;
  num_surface_ = sm.nodes.size();
  cad_face_ = sm.bface_cad_face;
  surface_tri_.reserve(sm.num_bfaces());
  for (std::size_t t = 0; t < sm.num_bfaces(); ++t)
    surface_tri_.emplace(tri_key(sm.bface(t)[0], sm.bface(t)[1], sm.bface(t)[2]),
                         static_cast<std::int32_t>(t));
  tet_volume_.resize(nt);
  const auto num_t = static_cast<std::ptrdiff_t>(nt);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t t = 0; t < num_t; ++t) {
    Vec3 x[4];
    for (int i = 0; i < 4; ++i) x[i] = tets.nodes[tets.tets[t][i]];
    tet_volume_[t] = volume(CellKind::Tet4, x);
  }
}

bool TetTopology::adjacent(std::int32_t a, std::int32_t b) const {
  return std::binary_search(neighbours_begin(a), neighbours_end(a), b);
}

std::int32_t TetTopology::surface_triangle(std::int32_t a, std::int32_t b, std::int32_t c) const {
  const std::int32_t* t = surface_tri_.find(tri_key(a, b, c));
  return t ? *t : -1;
}

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

namespace {

// Per kind, as bit sets over local corners: each face's corners, and the pairs of corners
// joined by an edge or by a quad's diagonal (bit 8 i + j, both ways round).
struct KindSets {
  int num_faces = 0;
  std::array<unsigned, 6> face{};
  std::array<bool, 6> quad{};
  std::uint64_t edge = 0, diagonal = 0;
};
KindSets kind_sets(CellKind kind) {
  KindSets k;
  const CellFaces cf = faces_of(kind);
  k.num_faces = cf.count;
  auto pair = [](int a, int b) {
    return (std::uint64_t{1} << (8 * a + b)) | (std::uint64_t{1} << (8 * b + a));
  };
  for (int f = 0; f < cf.count; ++f) {
    const LocalFace& lf = cf.face[f];
    for (int i = 0; i < lf.n; ++i) {
      k.face[f] |= 1u << lf.v[i];
      k.edge |= pair(lf.v[i], lf.v[(i + 1) % lf.n]);
    }
    k.quad[f] = lf.n == 4;
    if (k.quad[f]) k.diagonal |= pair(lf.v[0], lf.v[2]) | pair(lf.v[1], lf.v[3]);
  }
  return k;
}
const KindSets& sets_of(CellKind kind) {
  static const std::array<KindSets, kNumCellKinds> table = [] {
    std::array<KindSets, kNumCellKinds> t;
    for (int k = 0; k < kNumCellKinds; ++k) t[k] = kind_sets(static_cast<CellKind>(k));
    return t;
  }();
  return table[static_cast<int>(kind)];
}

}  // namespace

template <class Visit>
void ConformityIndex::for_each_at(std::int32_t v, Visit visit) const {
  if (static_cast<std::size_t>(v) >= at_.size()) return;
  const AtVertex& a = at_[v];
  for (int i = 0; i < std::min(a.count, 15); ++i) visit(a.element[i]);
  if (a.count <= 15) return;
  auto it = std::lower_bound(overflow_.begin(), overflow_.end(), std::pair{v, -1});
  for (; it != overflow_.end() && it->first == v; ++it) visit(it->second);
}

bool ConformityIndex::conflicts(const Candidate& c) const {
  const int nc = num_nodes(c.kind);
  near_.clear();
  for (int i = 0; i < nc; ++i)
    for_each_at(c.nodes[i], [&](std::int32_t e) {
      near_.push_back(static_cast<std::uint64_t>(e) << 8 | static_cast<unsigned>(i));
    });
  std::sort(near_.begin(), near_.end());
  const KindSets& cs = sets_of(c.kind);
  for (std::size_t i = 0; i < near_.size();) {
    std::size_t j = i + 1;
    while (j < near_.size() && near_[j] >> 8 == near_[i] >> 8) ++j;
    // Every rule needs two shared vertices.
    if (j - i < 2) {
      i = j;
      continue;
    }
    const Placed& e = placed_[near_[i] >> 8];
    // The candidate's corner at each of e's corners, or -1.
    int at[8];
    const int ne = num_nodes(e.kind);
    for (int k = 0; k < ne; ++k) {
      at[k] = -1;
      for (std::size_t s = i; s < j; ++s) {
        const int ci = static_cast<int>(near_[s] & 0xff);
        if (c.nodes[ci] == e.nodes[k]) at[k] = ci;
      }
    }
    i = j;
    const KindSets& es = sets_of(e.kind);
    // An edge of one on a diagonal of the other.
    for (int a = 0; a < ne; ++a) {
      if (at[a] < 0) continue;
      for (int b = a + 1; b < ne; ++b) {
        if (at[b] < 0) continue;
        const std::uint64_t ab = std::uint64_t{1} << (8 * a + b);
        const std::uint64_t cab = std::uint64_t{1} << (8 * at[a] + at[b]);
        if (((es.edge & ab) && (cs.diagonal & cab)) || ((es.diagonal & ab) && (cs.edge & cab)))
          return true;
      }
    }
    // A face of one holding three corners of a face of the other, one of the two a quad (two
    // quads holding all four corners are the same face: conformal).
    for (int f = 0; f < es.num_faces; ++f) {
      unsigned fc = 0;  // e's face f, in the candidate's corners
      for (int k = 0; k < ne; ++k)
        if ((es.face[f] >> k & 1u) && at[k] >= 0) fc |= 1u << at[k];
      if (std::popcount(fc) < 3) continue;
      for (int g = 0; g < cs.num_faces; ++g)
        if ((es.quad[f] || cs.quad[g]) && std::popcount(fc & cs.face[g]) == 3) return true;
    }
  }
  return false;
}

void ConformityIndex::reserve(std::size_t n) {
  placed_.reserve(n);
}

void ConformityIndex::add(const Candidate& c) {
  const auto id = static_cast<std::int32_t>(placed_.size());
  placed_.push_back({c.kind, c.nodes});
  for (int i = 0; i < num_nodes(c.kind); ++i) {
    const std::int32_t v = c.nodes[i];
    if (static_cast<std::size_t>(v) >= at_.size())
      at_.resize(std::max<std::size_t>(v + 1, 2 * at_.size()));
    AtVertex& a = at_[v];
    if (a.count < 15) {
      a.element[a.count] = id;
    } else {
      const std::pair<std::int32_t, std::int32_t> entry{v, id};
      overflow_.insert(std::upper_bound(overflow_.begin(), overflow_.end(), entry), entry);
    }
    ++a.count;
  }
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

std::vector<Candidate> collect_candidates(std::int32_t num_vertices, const FindCandidates& find) {
  std::vector<std::vector<Candidate>> runs;  // each thread's candidates, sorted, then merged
#pragma omp parallel
  {
    std::vector<Candidate> local;
    FillScratch scratch;
#pragma omp for schedule(dynamic, 256) nowait
    for (std::int32_t v = 0; v < num_vertices; ++v) find(v, scratch, local);
    std::sort(local.begin(), local.end());
#pragma omp critical
    runs.push_back(std::move(local));
  }
  // Candidates are distinct and totally ordered: the merged order does not depend on which
  // thread found what.
  std::vector<Candidate> all;
  if (runs.size() == 2) {
    // Two runs (two threads): each thread merges one half of the output, split where the first
    // k merged elements end (binary search on the merge path).
    const std::vector<Candidate>&A = runs[0], &B = runs[1];
    const std::size_t na = A.size(), nb = B.size(), k = (na + nb) / 2;
    std::size_t lo = k > nb ? k - nb : 0, hi = std::min(k, na);
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      if (A[mid] < B[k - mid - 1])
        lo = mid + 1;
      else
        hi = mid;
    }
    const std::size_t i = lo, j = k - lo;
    all.resize(na + nb);
#pragma omp parallel sections
    {
#pragma omp section
      std::merge(A.begin(), A.begin() + i, B.begin(), B.begin() + j, all.begin());
#pragma omp section
      std::merge(A.begin() + i, A.end(), B.begin() + j, B.end(), all.begin() + k);
    }
    return all;
  }
  std::vector<std::size_t> ends{0};
  for (const auto& r : runs) {
    all.insert(all.end(), r.begin(), r.end());
    ends.push_back(all.size());
  }
  for (std::size_t r = 2; r < ends.size(); ++r)
    std::inplace_merge(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(ends[r - 1]),
                       all.begin() + static_cast<std::ptrdiff_t>(ends[r]));
  return all;
}

QuadKey quad_corners(const Candidate& e, int local_face) {
  const LocalFace lf = faces_of(e.kind).face[local_face];
  QuadKey q;
  for (int i = 0; i < 4; ++i) q[i] = e.nodes[lf.v[i]];
  return q;
}

QuadKey quad_key(const Candidate& e, int local_face) {
  QuadKey k = quad_corners(e, local_face);
  std::sort(k.begin(), k.end());
  return k;
}

std::vector<KeyedTet> tets_by_corners(const TetTopology& topo,
                                      const std::vector<std::int32_t>& tets) {
  std::vector<KeyedTet> out;
  out.reserve(tets.size());
  for (std::int32_t t : tets) {
    QuadKey k = topo.mesh().tets[t];
    std::sort(k.begin(), k.end());
    out.push_back({k, t});
  }
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// std::sort on two threads: each sorts one half, then the halves are merged. Equal elements are
// indistinguishable here, so the result is std::sort's.
template <class T>
void sort_on_two_threads(std::vector<T>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
#pragma omp parallel sections
  {
#pragma omp section
    std::sort(v.begin(), mid);
#pragma omp section
    std::sort(mid, v.end());
  }
  std::inplace_merge(v.begin(), mid, v.end());
}

// Where each element's quad faces start in a list of all of them (and the total, last).
std::vector<std::size_t> quad_offsets(const std::vector<Candidate>& elements) {
  std::vector<std::size_t> off(elements.size() + 1, 0);
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const CellFaces cf = faces_of(elements[i].kind);
    std::size_t n = 0;
    for (int f = 0; f < cf.count; ++f) n += cf.face[f].n == 4;
    off[i + 1] = off[i] + n;
  }
  return off;
}

}  // namespace

std::vector<QuadKey> sorted_quad_keys(const std::vector<Candidate>& elements) {
  const std::vector<std::size_t> off = quad_offsets(elements);
  std::vector<QuadKey> keys(off.back());
  const auto n = static_cast<std::ptrdiff_t>(elements.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const Candidate& e = elements[i];
    const CellFaces cf = faces_of(e.kind);
    std::size_t at = off[i];
    for (int f = 0; f < cf.count; ++f)
      if (cf.face[f].n == 4) keys[at++] = quad_key(e, f);
  }
  sort_on_two_threads(keys);
  return keys;
}

bool quad_shared(const std::vector<QuadKey>& keys, const QuadKey& k) {
  const auto range = std::equal_range(keys.begin(), keys.end(), k);
  return range.second - range.first >= 2;
}

double tet_quality(const TetTopology& topo, std::int32_t t) {
  Vec3 x[4];
  for (int i = 0; i < 4; ++i) x[i] = topo.mesh().nodes[topo.mesh().tets[t][i]];
  return min_scaled_jacobian(CellKind::Tet4, x);
}

std::vector<std::int32_t> absorb_face_slivers(const TetTopology& topo,
                                              const std::vector<Candidate>& elements,
                                              std::vector<char>& used, SliverPolicy policy,
                                              double flat_sj) {
  // The free tets on the four corners of a quad face, with the policy's test, on all threads:
  // quad face i of the list (quad_offsets) -> its tet, -1 none, or -2 when it qualifies only if
  // the face is shared. Marking them used is left to the serial pass below, in face order.
  const std::vector<std::size_t> off = quad_offsets(elements);
  std::vector<std::int32_t> hit(off.back(), -1);
  const auto n = static_cast<std::ptrdiff_t>(elements.size());
  std::vector<QuadKey> ask;  // keys of the faces waiting on "shared"
#pragma omp parallel
  {
    std::vector<QuadKey> ask_local;
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < n; ++i) {
      const Candidate& e = elements[i];
      const CellFaces cf = faces_of(e.kind);
      std::size_t at = off[i];
      for (int f = 0; f < cf.count; ++f) {
        if (cf.face[f].n != 4) continue;
        const std::size_t slot = at++;
        const QuadKey k = quad_key(e, f);
        // A tet on the face's four corners has the lowest of them as its lowest vertex (at most
        // one tet has those four vertices).
        for (auto u = topo.upper_begin(k[0]); u != topo.upper_end(k[0]); ++u) {
          bool on_face = true;
          for (int j = 0; j < 3; ++j)
            on_face = on_face && (u->v[j] == k[1] || u->v[j] == k[2] || u->v[j] == k[3]);
          if (!on_face || used[u->tet]) continue;
          const std::int32_t t = u->tet;
          const auto& T = topo.mesh().tets[t];
          if (policy == SliverPolicy::kSharedOrBoundary) {
            int on_surface = 0;
            for (int skip = 0; skip < 4; ++skip)
              on_surface += topo.surface_triangle(T[(skip + 1) % 4], T[(skip + 2) % 4],
                                                  T[(skip + 3) % 4]) >= 0;
            if (on_surface < 2) {
              hit[slot] = -2 - t;
              ask_local.push_back(k);
              continue;
            }
          } else if (!(tet_quality(topo, t) < flat_sj)) {
            continue;
          }
          hit[slot] = t;
        }
      }
    }
#pragma omp critical
    ask.insert(ask.end(), ask_local.begin(), ask_local.end());
  }
  // How many elements have each asked face: one pass over all quad faces against the few asked.
  std::sort(ask.begin(), ask.end());
  ask.erase(std::unique(ask.begin(), ask.end()), ask.end());
  std::vector<int> count(ask.size(), 0);
  if (!ask.empty())
    for (const Candidate& e : elements) {
      const CellFaces cf = faces_of(e.kind);
      for (int f = 0; f < cf.count; ++f) {
        if (cf.face[f].n != 4) continue;
        const QuadKey k = quad_key(e, f);
        const auto it = std::lower_bound(ask.begin(), ask.end(), k);
        if (it != ask.end() && *it == k) ++count[it - ask.begin()];
      }
    }
  std::vector<std::int32_t> out;
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const CellFaces cf = faces_of(elements[i].kind);
    std::size_t at = off[i];
    for (int f = 0; f < cf.count; ++f) {
      if (cf.face[f].n != 4) continue;
      std::int32_t t = hit[at++];
      if (t == -1) continue;
      if (t <= -2) {
        t = -2 - t;
        const QuadKey k = quad_key(elements[i], f);
        if (count[std::lower_bound(ask.begin(), ask.end(), k) - ask.begin()] < 2) continue;
      }
      if (used[t]) continue;  // found from the other element on the face
      used[t] = 1;
      out.push_back(t);
    }
  }
  return out;
}

std::size_t release_orphan_slivers(const TetTopology& topo, const std::vector<Candidate>& elements,
                                   std::vector<std::int32_t>& absorbed, std::vector<char>& used,
                                   double flat_sj) {
  const std::vector<QuadKey> quads = sorted_quad_keys(elements);
  std::size_t released = 0, k = 0;
  for (std::int32_t t : absorbed) {
    QuadKey key = topo.mesh().tets[t];
    std::sort(key.begin(), key.end());
    const auto range = std::equal_range(quads.begin(), quads.end(), key);
    const auto faces = range.second - range.first;
    int on_surface = 0;
    const auto& T = topo.mesh().tets[t];
    for (int skip = 0; skip < 4; ++skip)
      on_surface +=
          topo.surface_triangle(T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]) >= 0;
    const bool keep =
        faces >= 2 || (faces == 1 && (on_surface >= 2 || tet_quality(topo, t) < flat_sj));
    if (keep) {
      absorbed[k++] = t;
    } else {
      used[t] = 0;
      ++released;
    }
  }
  absorbed.resize(k);
  return released;
}

std::vector<Candidate> place_greedily(const TetTopology& topo, std::vector<Candidate>& cands,
                                      std::vector<char>& used, ConformityIndex& index,
                                      const FillRules& rules) {
  if (!std::is_sorted(cands.begin(), cands.end())) std::sort(cands.begin(), cands.end());
  // Free tets around each vertex: a candidate with a corner whose tets are all taken cannot be
  // placed, and on big parts most candidates are rejected by this before any fill test.
  const TetMesh& m = topo.mesh();
  std::vector<std::int32_t> free_around(m.nodes.size(), 0);
  for (std::size_t t = 0; t < m.tets.size(); ++t)
    if (!used[t])
      for (std::int32_t v : m.tets[t]) ++free_around[v];
  auto possible = [&](const Candidate& c) {
    for (int i = 0; i < num_nodes(c.kind); ++i)
      if (free_around[c.nodes[i]] == 0) return false;
    return true;
  };
  // In chunks, best first: the fill tests of a chunk's still possible candidates on all threads
  // (they only read `used`), then the serial greedy pass over the chunk.
  constexpr std::size_t kChunk = 1 << 15;
  std::vector<char> fillable(std::min(cands.size(), kChunk));
  std::vector<Candidate> kept;
  for (std::size_t start = 0; start < cands.size(); start += kChunk) {
    const std::size_t end = std::min(cands.size(), start + kChunk);
    const auto count = static_cast<std::ptrdiff_t>(end - start);
#pragma omp parallel for schedule(dynamic, 256)
    for (std::ptrdiff_t k = 0; k < count; ++k) {
      Candidate& c = cands[start + k];
      fillable[k] = possible(c) && (c.tets[0] >= 0 || fills_element(topo, c, &used, rules));
    }
    for (std::size_t i = start; i < end; ++i) {
      const Candidate& c = cands[i];
      if (!fillable[i - start] || !possible(c)) continue;
      bool free = true;
      for (std::int32_t t : c.tets) free = free && (t < 0 || !used[t]);
      if (!free || index.conflicts(c)) continue;
      for (std::int32_t t : c.tets) {
        if (t < 0) continue;
        used[t] = 1;
        for (std::int32_t v : m.tets[t]) --free_around[v];
      }
      index.add(c);
      kept.push_back(c);
    }
  }
  return kept;
}

}  // namespace hexfem
