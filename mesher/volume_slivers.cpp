#include "mesher/volume_slivers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "mesher/mesh/quality.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

using Tet = std::array<std::int32_t, 4>;
constexpr int kMaxRing = 7;               // shells of up to 7 tets: 42 triangulations at most
constexpr double kMinFlipQuality = 1e-4;  // min scaled Jacobian of the tets a flip makes
// A flip must raise its shell's min by more than rounding: the same tet's quality, computed from
// its corners in another order, differs in the last bits, and a 4-tet shell flipped to its other
// diagonal and back "gained" 1.2e-16 each time, for ever (MVE_100-3 at h = 3.58: 16M flips and
// 11 GB before it was stopped).
constexpr double kMinFlipGain = 1e-9;

double orient(const std::vector<Vec3>& X, std::int32_t a, std::int32_t b, std::int32_t c,
              std::int32_t d) {
  const Vec3 &pa = X[a], &pb = X[b], &pc = X[c], &pd = X[d];
  const double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
  const double v[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
  const double w[3] = {pd[0] - pa[0], pd[1] - pa[1], pd[2] - pa[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

// The free tets as a mutable set: tets by id (TetGen's ids, then added ones), alive flags and
// the alive tets on each face.
class FreeTets {
 public:
  FreeTets(const TetTopology& topo, const std::vector<char>& used)
      : X_(topo.mesh().nodes), tets_(topo.mesh().tets), solid_(topo.mesh().tet_solid) {
    alive_.resize(tets_.size());
    quality_.resize(tets_.size());
    for (std::size_t t = 0; t < tets_.size(); ++t) {
      alive_[t] = !used[t];
      if (alive_[t]) add_faces(static_cast<std::int32_t>(t));
    }
  }
  std::size_t size() const { return tets_.size(); }
  bool alive(std::int32_t t) const { return alive_[t]; }
  const Tet& tet(std::int32_t t) const { return tets_[t]; }
  std::int32_t solid(std::int32_t t) const { return solid_[t]; }
  const std::vector<Vec3>& X() const { return X_; }
  double quality(std::int32_t t) {
    if (quality_[t] == 0) {
      Vec3 x[4];
      for (int i = 0; i < 4; ++i) x[i] = X_[tets_[t][i]];
      // Stored +2 so that 0 means "not computed" (qualities are in [-1, 1]).
      quality_[t] = 2 + min_scaled_jacobian(CellKind::Tet4, x);
    }
    return quality_[t] - 2;
  }
  // The alive tet other than `self` with face (a, b, c), or -1.
  std::int32_t across(std::int32_t self, std::int32_t a, std::int32_t b, std::int32_t c) const {
    auto it = faces_.find(tri_key(a, b, c));
    if (it == faces_.end()) return -1;
    for (std::int32_t t : it->second)
      if (t >= 0 && t != self) return t;
    return -1;
  }
  void kill(std::int32_t t) {
    alive_[t] = 0;
    for (int skip = 0; skip < 4; ++skip) {
      auto& slot = faces_[face(t, skip)];
      for (std::int32_t& s : slot)
        if (s == t) s = -1;
    }
  }
  std::int32_t add(const Tet& T, std::int32_t solid) {
    const auto id = static_cast<std::int32_t>(tets_.size());
    tets_.push_back(T);
    solid_.push_back(solid);
    alive_.push_back(1);
    quality_.push_back(0);
    add_faces(id);
    return id;
  }

 private:
  TriKey face(std::int32_t t, int skip) const {
    const Tet& T = tets_[t];
    return tri_key(T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]);
  }
  void add_faces(std::int32_t t) {
    for (int skip = 0; skip < 4; ++skip) {
      auto it = faces_.try_emplace(face(t, skip), std::array<std::int32_t, 2>{-1, -1}).first;
      auto& slot = it->second;
      (slot[0] < 0 ? slot[0] : slot[1]) = t;
    }
  }
  const std::vector<Vec3>& X_;
  std::vector<Tet> tets_;
  std::vector<std::int32_t> solid_;
  std::vector<char> alive_;
  std::vector<double> quality_;
  std::unordered_map<TriKey, std::array<std::int32_t, 2>, TriKeyHash> faces_;
};

// An edge removal: the shell's tets and the tets replacing them, with their min quality.
struct Flip {
  double old_min = 2, new_min = -2;
  std::vector<std::int32_t> shell;
  std::vector<Tet> added;
};

// Best edge removal of edge (p, q) of free tet t0, or new_min = -2 when there is none.
Flip remove_edge(FreeTets& ft, std::int32_t t0, std::int32_t p, std::int32_t q) {
  Flip f;
  const Tet& T = ft.tet(t0);
  std::int32_t r[2], n = 0;
  for (std::int32_t w : T)
    if (w != p && w != q) r[n++] = w;
  // Walk around the edge across faces (p, q, ring.back()) until the shell closes.
  std::vector<std::int32_t> ring{r[0], r[1]};
  f.shell.push_back(t0);
  for (std::int32_t cur = t0;;) {
    const std::int32_t next = ft.across(cur, p, q, ring.back());
    if (next < 0 || ft.solid(next) != ft.solid(t0)) return f;  // an element, or the surface
    std::int32_t x = -1;
    for (std::int32_t w : ft.tet(next))
      if (w != p && w != q && w != ring.back()) x = w;
    f.shell.push_back(next);
    if (x == r[0]) break;
    if (static_cast<int>(ring.size()) == kMaxRing || next == t0) return f;
    ring.push_back(x);
    cur = next;
  }
  if (f.shell.size() != ring.size()) return f;
  for (std::int32_t t : f.shell) f.old_min = std::min(f.old_min, ft.quality(t));
  // Ring orientation seen along p -> q: new tets (p, A, B, C) with A, B, C in ring order have
  // the sign of (p, q, r0, r1), those of q the other sign.
  const auto& X = ft.X();
  const double s = orient(X, p, q, ring[0], ring[1]) > 0 ? 1.0 : -1.0;
  const int m = static_cast<int>(ring.size());
  auto tri_quality = [&](int a, int b, int c) {
    const std::int32_t A = ring[a], B = ring[b], C = ring[c];
    if (!(s * orient(X, p, A, B, C) > 0) || !(s * orient(X, q, A, B, C) < 0)) return -2.0;
    Vec3 x[4];
    x[0] = X[p];
    x[1] = X[A];
    x[2] = X[s > 0 ? B : C];
    x[3] = X[s > 0 ? C : B];
    double qp = min_scaled_jacobian(CellKind::Tet4, x);
    x[0] = X[q];
    x[2] = X[s > 0 ? C : B];
    x[3] = X[s > 0 ? B : C];
    return std::min(qp, min_scaled_jacobian(CellKind::Tet4, x));
  };
  // Max-min triangulation of the ring polygon by dynamic programming over chains (i, j).
  double best[kMaxRing][kMaxRing];
  int pick[kMaxRing][kMaxRing];
  for (int len = 1; len < m; ++len)
    for (int i = 0; i + len < m; ++i) {
      const int j = i + len;
      best[i][j] = len == 1 ? 2.0 : -2.0;
      pick[i][j] = -1;
      for (int k = i + 1; k < j; ++k) {
        const double v = std::min({tri_quality(i, k, j), best[i][k], best[k][j]});
        if (v > best[i][j]) {
          best[i][j] = v;
          pick[i][j] = k;
        }
      }
    }
  if (!(best[0][m - 1] > -2)) return f;
  f.new_min = best[0][m - 1];
  std::vector<std::array<int, 2>> stack{{0, m - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int k = pick[i][j];
    const std::int32_t A = ring[i], B = ring[k], C = ring[j];
    f.added.push_back(s > 0 ? Tet{p, A, B, C} : Tet{p, A, C, B});
    f.added.push_back(s > 0 ? Tet{q, A, C, B} : Tet{q, A, B, C});
    stack.push_back({i, k});
    stack.push_back({k, j});
  }
  return f;
}

}  // namespace

SliverFlips flip_slivers(RecombineState& s) {
  const TetTopology& topo = s.topo;
  std::vector<char>& used = s.used;
  const double flat_sj = s.limits.sliver_quality;
  SliverFlips out;
  FreeTets ft(topo, used);
  const auto num_tetgen = static_cast<std::int32_t>(ft.size());
  // Passes until nothing improves; each flip raises the min quality of its shell by more than
  // kMinFlipGain, so no shell goes back to a triangulation it had. A pass visits the tets its own
  // flips add; as a guard it stops after as many flips as there were tets when it began.
  for (int pass = 0; pass < 4; ++pass) {
    bool changed = false;
    const std::size_t max_flips = out.flips + ft.size();
    for (std::int32_t t = 0; t < static_cast<std::int32_t>(ft.size()) && out.flips < max_flips;
         ++t) {
      if (!ft.alive(t) || !(ft.quality(t) < flat_sj)) continue;
      Flip best;
      const Tet T = ft.tet(t);
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          Flip f = remove_edge(ft, t, T[i], T[j]);
          // Never trade a flat tet for another nearly flat one (rounding could invert it).
          if (f.new_min > std::max(f.old_min + kMinFlipGain, kMinFlipQuality) &&
              f.new_min > best.new_min)
            best = std::move(f);
        }
      if (best.new_min <= -2) continue;
      const std::int32_t solid = ft.solid(t);
      for (std::int32_t k : best.shell) ft.kill(k);
      for (const Tet& n : best.added) ft.add(n, solid);
      ++out.flips;
      changed = true;
    }
    if (!changed) break;
  }
  for (std::int32_t t = 0; t < static_cast<std::int32_t>(ft.size()); ++t) {
    if (t < num_tetgen) {
      if (!used[t] && !ft.alive(t)) {
        used[t] = 1;
        out.removed.push_back(t);
      }
    } else if (ft.alive(t)) {
      out.added.push_back(ft.tet(t));
      out.added_solid.push_back(ft.solid(t));
    }
    if (ft.alive(t) && ft.quality(t) < flat_sj) ++out.slivers_left;
  }
  return out;
}

namespace {
bool on_interface(const std::vector<char>& interface_face, std::int32_t cad_face) {
  return cad_face >= 0 && cad_face < static_cast<std::int32_t>(interface_face.size()) &&
         interface_face[cad_face];
}
}  // namespace

std::vector<char> interface_faces(const SurfaceMesh& surface) {
  std::vector<int> count;
  for (const auto& faces : surface.faces_of_solid)
    for (int f : faces) {
      if (f >= static_cast<int>(count.size())) count.resize(f + 1, 0);
      ++count[f];
    }
  std::vector<char> out(count.size(), 0);
  for (std::size_t f = 0; f < count.size(); ++f) out[f] = count[f] > 1;
  return out;
}

namespace {

// Every edge of the surface triangles.
std::unordered_set<std::uint64_t> surface_edges(const MixedMesh& sm) {
  std::unordered_set<std::uint64_t> edges;
  edges.reserve(sm.num_bfaces() * 3 / 2);
  for (std::size_t f = 0; f < sm.num_bfaces(); ++f)
    for (int i = 0; i < 3; ++i) edges.insert(edge_key(sm.bface(f)[i], sm.bface(f)[(i + 1) % 3]));
  return edges;
}

}  // namespace

std::size_t drop_flat_boundary_tets(TetMesh& tets, SurfaceMesh& surface, double flat_sj) {
  MixedMesh& sm = surface.mesh;
  std::unordered_map<TriKey, std::int32_t, TriKeyHash> tri;
  tri.reserve(sm.num_bfaces());
  for (std::size_t f = 0; f < sm.num_bfaces(); ++f)
    tri.emplace(tri_key(sm.bface(f)[0], sm.bface(f)[1], sm.bface(f)[2]),
                static_cast<std::int32_t>(f));
  // Surface edges: the diagonal a dropped tet gives the surface must not be one already (where
  // a thin part's sharp edge runs along the tet, that edge would then be in four triangles and
  // the boundary no longer a closed manifold: Propeller.rle at h = 45.29).
  std::unordered_set<std::uint64_t> edges = surface_edges(sm);
  // CAD faces between two glued solids (--glue): tets lie on both sides, so a flat one there is
  // no gap to close by turning the surface diagonal; the other side's tets hold the old one
  // (flip_flat_interface_tets handles it).
  const std::vector<char> interface_face = interface_faces(surface);
  const auto& X = tets.nodes;
  auto normal = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    const Vec3 u{X[b][0] - X[a][0], X[b][1] - X[a][1], X[b][2] - X[a][2]};
    const Vec3 v{X[c][0] - X[a][0], X[c][1] - X[a][1], X[c][2] - X[a][2]};
    return Vec3{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  };
  auto dot = [](const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  // The flat tets with four surface corners (two surface faces span all four), found on all
  // threads; the serial pass below looks only at them. Testing the corners first keeps the
  // millions of flat interior tets of a large part (Propeller at h = 1) out of the hash lookups.
  std::vector<std::int32_t> flat;
  const auto nt = static_cast<std::ptrdiff_t>(tets.tets.size());
  const auto num_surface = static_cast<std::int32_t>(sm.nodes.size());
  std::vector<char> is_flat(tets.tets.size());
#pragma omp parallel for schedule(static, 4096)
  for (std::ptrdiff_t t = 0; t < nt; ++t) {
    const Tet& T = tets.tets[t];
    if (T[0] >= num_surface || T[1] >= num_surface || T[2] >= num_surface || T[3] >= num_surface) {
      is_flat[t] = 0;
      continue;
    }
    Vec3 x[4];
    for (int i = 0; i < 4; ++i) x[i] = X[tets.tets[t][i]];
    is_flat[t] = min_scaled_jacobian(CellKind::Tet4, x) < flat_sj;
  }
  for (std::ptrdiff_t t = 0; t < nt; ++t)
    if (is_flat[t]) flat.push_back(static_cast<std::int32_t>(t));
  std::vector<char> drop(tets.tets.size(), 0);
  std::size_t dropped = 0;
  for (const std::int32_t t : flat) {
    const Tet& T = tets.tets[t];
    // Faces by the corner they skip; which are surface triangles.
    std::int32_t sf[4];
    int ns = 0, on[2] = {-1, -1}, off[2] = {-1, -1}, no = 0;
    for (int skip = 0; skip < 4; ++skip) {
      auto it = tri.find(tri_key(T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]));
      sf[skip] = it == tri.end() ? -1 : it->second;
      if (sf[skip] >= 0) {
        if (ns < 2) on[ns] = skip;
        ++ns;
      } else if (no < 2) {
        off[no++] = skip;
      }
    }
    if (ns != 2) continue;
    const std::int32_t s1 = sf[on[0]], s2 = sf[on[1]];
    if (sm.bface_cad_face[s1] != sm.bface_cad_face[s2] ||
        on_interface(interface_face, sm.bface_cad_face[s1]))
      continue;
    const std::int32_t* A = sm.bface(s1);
    const std::int32_t* B = sm.bface(s2);
    const Vec3 n1 = normal(A[0], A[1], A[2]), n2 = normal(B[0], B[1], B[2]);
    if (!(dot(n1, n2) > 0)) continue;  // a fold, not the two halves of one flat quad
    // The old diagonal joins the corners both surface faces hold, the new one the other two.
    const std::int32_t na = T[on[0]], nb = T[on[1]];
    const std::uint64_t new_diag = edge_key(na, nb);
    if (edges.count(new_diag)) continue;
    std::int32_t old_diag[2], k_old = 0;
    for (int i = 0; i < 4; ++i)
      if (i != on[0] && i != on[1]) old_diag[k_old++] = T[i];
    // The two other faces, oriented like the surface (outward).
    std::array<std::int32_t, 3> nf[2];
    for (int k = 0; k < 2; ++k) {
      const int skip = off[k];
      nf[k] = {T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]};
      if (dot(normal(nf[k][0], nf[k][1], nf[k][2]), n1) < 0) std::swap(nf[k][1], nf[k][2]);
    }
    tri.erase(tri_key(A[0], A[1], A[2]));
    tri.erase(tri_key(B[0], B[1], B[2]));
    const std::int32_t slot[2] = {s1, s2};
    for (int k = 0; k < 2; ++k) {
      std::int32_t* f = &sm.bface_nodes[4 * slot[k]];
      f[0] = nf[k][0];
      f[1] = nf[k][1];
      f[2] = nf[k][2];
      tri.emplace(tri_key(f[0], f[1], f[2]), slot[k]);
    }
    edges.erase(edge_key(old_diag[0], old_diag[1]));
    edges.insert(new_diag);
    drop[t] = 1;
    ++dropped;
  }
  if (dropped) {
    std::size_t k = 0;
    for (std::size_t t = 0; t < tets.tets.size(); ++t) {
      if (drop[t]) continue;
      tets.tets[k] = tets.tets[t];
      tets.tet_solid[k++] = tets.tet_solid[t];
    }
    tets.tets.resize(k);
    tets.tet_solid.resize(k);
  }
  return dropped;
}

std::size_t flip_flat_interface_tets(TetMesh& tets, SurfaceMesh& surface, double flat_sj) {
  const std::vector<char> interface_face = interface_faces(surface);
  MixedMesh& sm = surface.mesh;
  if (std::find(interface_face.begin(), interface_face.end(), 1) == interface_face.end()) return 0;
  std::unordered_map<TriKey, std::int32_t, TriKeyHash> tri;
  for (std::size_t f = 0; f < sm.num_bfaces(); ++f)
    tri.emplace(tri_key(sm.bface(f)[0], sm.bface(f)[1], sm.bface(f)[2]),
                static_cast<std::int32_t>(f));
  const auto& X = tets.nodes;
  auto face_of = [&](const Tet& T, int skip) {
    return tri_key(T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]);
  };
  // Flat tets with two surface faces, one at least on an interface (where an interface face
  // meets an outer face in one plane, the two may differ): their two other faces, to find the
  // tets across them.
  struct Flat {
    std::int32_t t;
    double sj;  // its min scaled Jacobian
    int on[2], off[2];
    bool one_face;  // both surface faces on the same CAD face
  };
  std::vector<Flat> flat;
  std::unordered_map<TriKey, std::array<std::int32_t, 2>, TriKeyHash> across;
  for (std::size_t t = 0; t < tets.tets.size(); ++t) {
    const Tet& T = tets.tets[t];
    Vec3 x[4];
    for (int i = 0; i < 4; ++i) x[i] = X[T[i]];
    const double sj = min_scaled_jacobian(CellKind::Tet4, x);
    if (!(sj < flat_sj)) continue;
    Flat f{static_cast<std::int32_t>(t), sj, {-1, -1}, {-1, -1}, false};
    int ns = 0, no = 0;
    std::int32_t cad[2] = {-1, -1};
    for (int skip = 0; skip < 4; ++skip) {
      const auto it = tri.find(face_of(T, skip));
      if (it != tri.end() && ns < 2) {
        cad[ns] = sm.bface_cad_face[it->second];
        f.on[ns++] = skip;
      } else if (it == tri.end() && no < 2) {
        f.off[no++] = skip;
      }
    }
    if (ns != 2 || no != 2 ||
        !(on_interface(interface_face, cad[0]) || on_interface(interface_face, cad[1])))
      continue;
    f.one_face = cad[0] == cad[1];
    flat.push_back(f);
    for (int k = 0; k < 2; ++k) {
      across.emplace(face_of(T, f.off[k]), std::array<std::int32_t, 2>{-1, -1});
      across.emplace(face_of(T, f.on[k]), std::array<std::int32_t, 2>{-1, -1});
    }
  }
  if (flat.empty()) return 0;
  // The 2-2 flip below gives the surface a new diagonal, which must not be a surface edge
  // already (as in drop_flat_boundary_tets: it would then lie in four triangles).
  std::unordered_set<std::uint64_t> edges = surface_edges(sm);
  // Only a tet with three corners among the flat tets' can hold one of their faces: the others
  // skip the lookups.
  std::vector<char> at_flat(X.size(), 0);
  for (const Flat& f : flat)
    for (std::int32_t v : tets.tets[f.t]) at_flat[v] = 1;
  for (std::size_t t = 0; t < tets.tets.size(); ++t) {
    const Tet& T = tets.tets[t];
    if (at_flat[T[0]] + at_flat[T[1]] + at_flat[T[2]] + at_flat[T[3]] < 3) continue;
    for (int skip = 0; skip < 4; ++skip) {
      const auto it = across.find(face_of(T, skip));
      if (it == across.end()) continue;
      auto& slot = it->second;
      (slot[0] < 0 ? slot[0] : slot[1]) = static_cast<std::int32_t>(t);
    }
  }
  std::vector<char> gone(tets.tets.size(), 0);
  std::vector<Tet> added;
  std::vector<std::int32_t> added_solid;
  for (const Flat& f : flat) {
    const Tet T = tets.tets[f.t];
    if (gone[f.t]) continue;
    // The tets across the faces `skips` of T, if both exist, and their common fourth vertex.
    auto pair_across = [&](const int(&skips)[2], std::int32_t(&n)[2]) -> std::int32_t {
      std::int32_t apex[2] = {-1, -1};
      for (int k = 0; k < 2; ++k) {
        const auto& slot = across.at(face_of(T, skips[k]));
        n[k] = slot[0] == f.t ? slot[1] : slot[0];
        if (n[k] < 0 || gone[n[k]]) return -1;
        for (std::int32_t v : tets.tets[n[k]])
          if (v != T[0] && v != T[1] && v != T[2] && v != T[3]) apex[k] = v;
      }
      return n[0] != n[1] && apex[0] >= 0 && apex[0] == apex[1] ? apex[0] : -1;
    };
    // Tets (face of T skipped by skips[k], b), positively oriented; false if one is not better
    // than T and kMinFlipQuality (as in flip_slivers). They may stay below flat_sj: where the
    // fuse left two surface nodes microns apart (AS1 at h = 3: a needle triangle on an outer face
    // in the interface's plane), every tet on that needle is a sliver, but not a flat cell.
    const double floor = std::max(f.sj, kMinFlipQuality);
    auto make = [&](const int(&skips)[2], std::int32_t b, Tet(&nt)[2]) {
      for (int k = 0; k < 2; ++k) {
        const int skip = skips[k];
        nt[k] = {T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4], b};
        Vec3 x[4];
        for (int i = 0; i < 4; ++i) x[i] = X[nt[k][i]];
        const Vec3 u = v3::sub(x[1], x[0]), v = v3::sub(x[2], x[0]), w = v3::sub(x[3], x[0]);
        if (v3::dot(v3::cross(u, v), w) < 0) std::swap(nt[k][1], nt[k][2]);
        for (int i = 0; i < 4; ++i) x[i] = X[nt[k][i]];
        if (!(min_scaled_jacobian(CellKind::Tet4, x) > floor)) return false;
      }
      return true;
    };
    auto replace = [&](std::int32_t(&n)[2], const Tet(&nt)[2], std::int32_t solid) {
      gone[f.t] = gone[n[0]] = gone[n[1]] = 1;
      for (const Tet& t : nt) {
        added.push_back(t);
        added_solid.push_back(solid);
      }
    };
    std::int32_t n[2];
    Tet nt[2];
    // Its own side: the tets across its inner faces and T are the pyramid (the flat quad, apex
    // b), split again along the interface's diagonal (a 3-2 flip).
    std::int32_t b = pair_across(f.off, n);
    if (b >= 0 && tets.tet_solid[n[0]] == tets.tet_solid[f.t] &&
        tets.tet_solid[n[1]] == tets.tet_solid[f.t] && make(f.on, b, nt)) {
      replace(n, nt, tets.tet_solid[f.t]);
      continue;
    }
    // Else the other solid's side: its two tets on the interface triangles, when they share an
    // apex, are split along T's inner diagonal instead (a 2-2 flip), the interface takes that
    // diagonal, and T goes.
    if (!f.one_face) continue;
    const std::uint64_t new_diag = edge_key(T[f.on[0]], T[f.on[1]]);
    if (edges.count(new_diag)) continue;
    b = pair_across(f.on, n);
    if (b < 0 || tets.tet_solid[n[0]] != tets.tet_solid[n[1]] || !make(f.off, b, nt)) continue;
    std::int32_t slot[2];
    for (int k = 0; k < 2; ++k) slot[k] = tri.at(face_of(T, f.on[k]));
    const std::int32_t* A = sm.bface(slot[0]);
    const Vec3 n1 = v3::cross(v3::sub(X[A[1]], X[A[0]]), v3::sub(X[A[2]], X[A[0]]));
    replace(n, nt, tets.tet_solid[n[0]]);
    edges.erase(edge_key(T[f.off[0]], T[f.off[1]]));
    edges.insert(new_diag);
    for (int k = 0; k < 2; ++k) {
      const int skip = f.off[k];
      std::int32_t* fn = &sm.bface_nodes[4 * slot[k]];
      fn[0] = T[(skip + 1) % 4];
      fn[1] = T[(skip + 2) % 4];
      fn[2] = T[(skip + 3) % 4];
      const Vec3 nk = v3::cross(v3::sub(X[fn[1]], X[fn[0]]), v3::sub(X[fn[2]], X[fn[0]]));
      if (v3::dot(nk, n1) < 0) std::swap(fn[1], fn[2]);
    }
  }
  std::size_t k = 0;
  for (std::size_t t = 0; t < tets.tets.size(); ++t) {
    if (gone[t]) continue;
    tets.tets[k] = tets.tets[t];
    tets.tet_solid[k++] = tets.tet_solid[t];
  }
  const std::size_t flipped = (tets.tets.size() - k) / 3;  // each flip took three tets
  tets.tets.resize(k);
  tets.tet_solid.resize(k);
  tets.tets.insert(tets.tets.end(), added.begin(), added.end());
  tets.tet_solid.insert(tets.tet_solid.end(), added_solid.begin(), added_solid.end());
  return flipped;
}

namespace {

// Min scaled Jacobian of a cell, -1 when some corner is inverted (the pyramid apex included).
double cell_score(const MixedMesh& mesh, std::size_t c) {
  return cell_is_inverted(mesh, c) ? -1.0 : cell_min_scaled_jacobian(mesh, c);
}

}  // namespace

std::size_t lift_slivers(MixedMesh& mesh, std::size_t num_fixed_nodes, double below) {
  const std::size_t nc = mesh.num_cells();
  std::vector<std::size_t> bad;
  std::vector<double> floor(nc);
  std::vector<char> is_bad(nc);
  const auto count = static_cast<std::ptrdiff_t>(nc);
#pragma omp parallel for schedule(static, 4096)
  for (std::ptrdiff_t c = 0; c < count; ++c) {
    const double s = cell_score(mesh, c);
    const CellKind k = mesh.cell_kind[c];
    const double kind_floor = k == CellKind::Tet4 ? -1.0 : k == CellKind::Pyramid5 ? 0.05 : 0.3;
    floor[c] = std::min(s, kind_floor);
    is_bad[c] = s < below;
  }
  for (std::size_t c = 0; c < nc; ++c)
    if (is_bad[c]) bad.push_back(c);
  if (bad.empty()) return 0;
  // Cells at each node (CSR).
  std::vector<std::int32_t> off(mesh.nodes.size() + 1, 0), star;
  for (std::size_t c = 0; c < nc; ++c)
    for (int i = 0; i < num_nodes(mesh.cell_kind[c]); ++i) ++off[mesh.cell(c)[i] + 1];
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) off[v + 1] += off[v];
  star.resize(off.back());
  {
    std::vector<std::int32_t> fill(off.begin(), off.end() - 1);
    for (std::size_t c = 0; c < nc; ++c)
      for (int i = 0; i < num_nodes(mesh.cell_kind[c]); ++i)
        star[fill[mesh.cell(c)[i]]++] = static_cast<std::int32_t>(c);
  }
  // The worst cell at p, or -2 when a hex, prism or pyramid would fall below its floor.
  auto star_score = [&](std::int32_t p) {
    double s = 1;
    for (std::int32_t k = off[p]; k < off[p + 1]; ++k) {
      const double q = cell_score(mesh, star[k]);
      if (mesh.cell_kind[star[k]] != CellKind::Tet4 && q < floor[star[k]]) return -2.0;
      s = std::min(s, q);
    }
    return s;
  };
  std::size_t lifted = 0;
  for (std::size_t c : bad) {
    if (cell_score(mesh, c) >= below) continue;  // an earlier move fixed it
    const int n = num_nodes(mesh.cell_kind[c]);
    const std::int32_t* cn = mesh.cell(c);
    double edge = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        edge += v3::norm(v3::sub(mesh.nodes[cn[i]], mesh.nodes[cn[j]]));
    edge /= n * (n - 1) / 2;
    // Trial directions: the axes, and the normal of each corner's opposite triangle.
    std::vector<Vec3> dirs = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i + 2 < n; ++i) {
      const Vec3 nv = v3::cross(v3::sub(mesh.nodes[cn[i + 1]], mesh.nodes[cn[i]]),
                                v3::sub(mesh.nodes[cn[i + 2]], mesh.nodes[cn[i]]));
      if (v3::norm(nv) > 0) dirs.push_back(v3::scaled(nv, 1 / v3::norm(nv)));
    }
    std::int32_t best_node = -1;
    Vec3 best_pos{};
    double gain = 0;  // best rise of the worst cell at the moved vertex
    for (int i = 0; i < n; ++i) {
      const std::int32_t p = cn[i];
      if (static_cast<std::size_t>(p) < num_fixed_nodes) continue;
      const Vec3 x0 = mesh.nodes[p];
      const double now = star_score(p);
      for (double step : {0.02, 0.05, 0.1, 0.2})
        for (const Vec3& d : dirs)
          for (double sign : {1.0, -1.0}) {
            const Vec3 move = v3::scaled(d, sign * step * edge);
            mesh.nodes[p] = {x0[0] + move[0], x0[1] + move[1], x0[2] + move[2]};
            const double s = star_score(p);
            if (s - now > gain) {
              gain = s - now;
              best_node = p;
              best_pos = mesh.nodes[p];
            }
          }
      mesh.nodes[p] = x0;
    }
    if (best_node < 0) continue;
    mesh.nodes[best_node] = best_pos;
    ++lifted;
  }
  return lifted;
}

std::vector<Vec3> points_beside_flat_tets(const MixedMesh& mesh, const SolidLocator& locator) {
  const auto& X = mesh.nodes;
  std::vector<std::size_t> flat;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    if (mesh.cell_kind[c] == CellKind::Tet4 &&
        cell_min_scaled_jacobian(mesh, c) < kDegenerateScaledJacobian)
      flat.push_back(c);
  std::vector<Vec3> out;
  if (flat.empty()) return out;
  // The cells at each node (only the flat tets' nodes are asked).
  std::unordered_map<std::int32_t, std::vector<std::size_t>> cells_at;
  for (std::size_t c : flat)
    for (int i = 0; i < 4; ++i) cells_at[mesh.cell(c)[i]];
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    for (int i = 0; i < num_nodes(mesh.cell_kind[c]); ++i) {
      const auto it = cells_at.find(mesh.cell(c)[i]);
      if (it != cells_at.end()) it->second.push_back(c);
    }
  for (std::size_t c : flat) {
    const std::int32_t* T = mesh.cell(c);
    Vec3 g{0, 0, 0};
    for (int i = 0; i < 4; ++i) g = v3::add(g, v3::scaled(X[T[i]], 0.25));
    // The plane: the normal of the largest face.
    Vec3 n{0, 0, 0};
    double best = 0;  // its squared length
    for (int skip = 0; skip < 4; ++skip) {
      const Vec3& a = X[T[(skip + 1) % 4]];
      const Vec3 w = v3::cross(v3::sub(X[T[(skip + 2) % 4]], a), v3::sub(X[T[(skip + 3) % 4]], a));
      if (v3::dot(w, w) > best) {
        best = v3::dot(w, w);
        n = w;
      }
    }
    if (!(best > 0)) continue;
    for (double& x : n) x /= std::sqrt(best);
    // The farthest corner, off the plane, of the cells on the tet's faces.
    double far = 0;
    for (int i = 0; i < 4; ++i)
      for (std::size_t o : cells_at[T[i]]) {
        if (o == c) continue;
        const std::int32_t* O = mesh.cell(o);
        const int no = num_nodes(mesh.cell_kind[o]);
        int shared = 0;
        for (int k = 0; k < no; ++k)
          shared += O[k] == T[0] || O[k] == T[1] || O[k] == T[2] || O[k] == T[3];
        if (shared < 3) continue;
        for (int k = 0; k < no; ++k) {
          const double d = v3::dot(v3::sub(X[O[k]], g), n);
          if (std::abs(d) > std::abs(far)) far = d;
        }
      }
    if (far == 0) continue;
    const Vec3 p = v3::add(g, v3::scaled(n, 0.3 * far));
    if (locator.inside(mesh.cell_solid[c], p)) out.push_back(p);
  }
  return out;
}

}  // namespace hexfem
