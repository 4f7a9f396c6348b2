#include "mesher/recombine_tets.hpp"

#include <algorithm>

#include "mesher/mesh/parallel.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

TriKey tri_key(std::int32_t a, std::int32_t b, std::int32_t c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {{a, b, c}};
}

TetTopology::TetTopology(const TetMesh& tets, const SurfaceMesh& surface) : mesh_(tets) {
  const std::size_t nv = tets.nodes.size(), nt = tets.tets.size();
  // Star: a counting sort by vertex keeps tets in increasing order around each vertex.
  star_.resize(4 * nt);
  parallel_bucket_items(
      nt, nv,
      [&](std::size_t t, auto&& f) {
        for (std::int32_t v : tets.tets[t]) f(v);
      },
      star_off_,
      [&](std::size_t i, std::size_t t, std::int32_t) { star_[i] = static_cast<std::int32_t>(t); });
  // Upper: each tet at its lowest vertex, its other three in cyclic order from it.
  upper_.resize(nt);
  parallel_bucket_items(
      nt, nv,
      [&](std::size_t t, auto&& f) {
        const auto& T = tets.tets[t];
        f(*std::min_element(T.begin(), T.end()));
      },
      upper_off_,
      [&](std::size_t i, std::size_t t, std::int32_t) {
        const auto& T = tets.tets[t];
        const int lo = static_cast<int>(std::min_element(T.begin(), T.end()) - T.begin());
        UpperTet& u = upper_[i];
        u.tet = static_cast<std::int32_t>(t);
        for (int k = 1; k < 4; ++k) u.v[k - 1] = T[(lo + k) % 4];
      });
  // Neighbours: the other vertices of the star, sorted and unique, made on all threads and
  // joined in vertex order (no buffer of three times the star: 300 MB of fresh pages on a
  // million-vertex part).
  std::vector<std::int32_t> count(nv);
  const auto add_neighbours = [&](std::size_t v, std::vector<std::int32_t>& out) {
    const std::size_t begin = out.size();
    const auto self = static_cast<std::int32_t>(v);
    // The stars' tets lie all over memory: those of the vertex after next are asked for now,
    // so that their misses overlap this vertex's work.
    if (v + 2 < nv) {
      const auto ahead = static_cast<std::int32_t>(v + 2);
      for (auto it = star_begin(ahead); it != star_end(ahead); ++it)
        __builtin_prefetch(&tets.tets[*it]);
    }
    // Each neighbour turns up in several tets of the star: kept once by a small hash table on
    // the stack (sorting all of them was most of the work), then the few left are sorted.
    constexpr std::size_t kSlots = 256;
    if (3 * static_cast<std::size_t>(star_end(self) - star_begin(self)) <= kSlots / 2) {
      std::int32_t slot[kSlots];
      std::fill(slot, slot + kSlots, -1);
      for (auto it = star_begin(self); it != star_end(self); ++it)
        for (std::int32_t w : tets.tets[*it]) {
          if (w == self) continue;
          std::size_t h = static_cast<std::uint32_t>(w) * 0x9E3779B1u >> 24;
          while (slot[h] >= 0 && slot[h] != w) h = (h + 1) % kSlots;
          if (slot[h] < 0) {
            slot[h] = w;
            out.push_back(w);
          }
        }
      std::sort(out.begin() + begin, out.end());
    } else {
      for (auto it = star_begin(self); it != star_end(self); ++it)
        for (std::int32_t w : tets.tets[*it])
          if (w != self) out.push_back(w);
      std::sort(out.begin() + begin, out.end());
      out.erase(std::unique(out.begin() + begin, out.end()), out.end());
    }
    count[v] = static_cast<std::int32_t>(out.size() - begin);
  };
  // About 15 neighbours a vertex: room reserved up front, so the lists never grow by copying.
  adj_ = parallel_collect<std::int32_t>(nv, add_neighbours, 20 * nv);
  adj_off_.assign(nv + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) adj_off_[v + 1] = adj_off_[v] + count[v];
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

std::int32_t TetTopology::tet_across(std::int32_t skip, std::int32_t a, std::int32_t b,
                                     std::int32_t c) const {
  for (auto it = star_begin(a); it != star_end(a); ++it) {
    if (*it == skip) continue;
    const auto& T = mesh_.tets[*it];
    const bool hb = T[0] == b || T[1] == b || T[2] == b || T[3] == b;
    const bool hc = T[0] == c || T[1] == c || T[2] == c || T[3] == c;
    if (hb && hc) return *it;
  }
  return -1;
}

std::int32_t TetTopology::surface_triangle(std::int32_t a, std::int32_t b, std::int32_t c) const {
  // A triangle with an interior vertex is not on the surface: most queries end here, without a
  // hash lookup.
  const auto ns = static_cast<std::int32_t>(num_surface_);
  if (a >= ns || b >= ns || c >= ns) return -1;
  const std::int32_t* t = surface_tri_.find(tri_key(a, b, c));
  return t ? *t : -1;
}

double tet_quality(const TetTopology& topo, std::int32_t t) {
  Vec3 x[4];
  for (int i = 0; i < 4; ++i) x[i] = topo.mesh().nodes[topo.mesh().tets[t][i]];
  return min_scaled_jacobian(CellKind::Tet4, x);
}

}  // namespace hexfem
