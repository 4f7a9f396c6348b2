#include "mesher/recombine_slivers.hpp"

#include <algorithm>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

TetsByCorners::TetsByCorners(const TetTopology& topo, const std::vector<std::int32_t>& tets)
    : map_(tets.size()), filter_(std::size_t{1} << (kFilterBits - 6), 0) {
  for (const std::int32_t t : tets) {
    QuadKey k = topo.mesh().tets[t];
    std::sort(k.begin(), k.end());
    map_.emplace(k, t);
    const std::uint64_t b = Hash{}(k) >> (64 - kFilterBits);
    filter_[b >> 6] |= std::uint64_t{1} << (b & 63);
  }
}

void parallel_for_quad_faces(const std::vector<Candidate>& elements,
                             const std::function<void(std::size_t, int)>& visit) {
  const auto n = static_cast<std::ptrdiff_t>(elements.size());
#pragma omp parallel for schedule(static, 1024)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const CellFaces& cf = faces_of(elements[i].kind);
    for (int f = 0; f < cf.count; ++f)
      if (cf.face[f].n == 4) visit(static_cast<std::size_t>(i), f);
  }
}

QuadFaces::QuadFaces(const std::vector<Candidate>& elements, std::size_t num_vertices)
    : off_(num_vertices + 1, 0), match_(6 * elements.size(), kAlone) {
  // A counting sort by lowest corner, a pass to count and one to file, each thread over all
  // elements but only for its range of vertices: the writes scatter over all faces, and each
  // thread takes its share of them.
  std::vector<std::int32_t> fill;
#pragma omp parallel
  {
    int threads = 1, me = 0;
#ifdef _OPENMP
    threads = omp_get_num_threads();
    me = omp_get_thread_num();
#endif
    const auto lo = static_cast<std::int32_t>(num_vertices * me / threads);
    const auto hi = static_cast<std::int32_t>(num_vertices * (me + 1) / threads);
    for (const Candidate& e : elements) {
      const CellFaces cf = faces_of(e.kind);
      for (int f = 0; f < cf.count; ++f) {
        const LocalFace& lf = cf.face[f];
        if (lf.n != 4) continue;
        const std::int32_t m =
            std::min({e.nodes[lf.v[0]], e.nodes[lf.v[1]], e.nodes[lf.v[2]], e.nodes[lf.v[3]]});
        if (m >= lo && m < hi) ++off_[m + 1];
      }
    }
#pragma omp barrier
#pragma omp single
    {
      for (std::size_t v = 0; v < num_vertices; ++v) off_[v + 1] += off_[v];
      face_.resize(off_.back());
      fill.assign(off_.begin(), off_.end() - 1);
    }
    for (std::size_t i = 0; i < elements.size(); ++i) {
      const CellFaces cf = faces_of(elements[i].kind);
      for (int f = 0; f < cf.count; ++f) {
        if (cf.face[f].n != 4) continue;
        const QuadKey k = quad_key(elements[i], f);
        if (k[0] >= lo && k[0] < hi)
          face_[fill[k[0]]++] = {{k[1], k[2], k[3]}, static_cast<std::int32_t>(6 * i + f)};
      }
    }
#pragma omp barrier
    // Faces with equal corners are in one vertex's list.
#pragma omp for schedule(static, 4096)
    for (std::int32_t v = 0; v < static_cast<std::int32_t>(num_vertices); ++v)
      for (std::int32_t i = off_[v]; i < off_[v + 1]; ++i) {
        int same = 0;
        std::int32_t other = kAlone;
        for (std::int32_t j = off_[v]; j < off_[v + 1]; ++j)
          if (j != i && face_[j].v[0] == face_[i].v[0] && face_[j].v[1] == face_[i].v[1] &&
              face_[j].v[2] == face_[i].v[2]) {
            ++same;
            other = face_[j].slot;
          }
        match_[face_[i].slot] = same == 0 ? kAlone : same == 1 ? other : kMany;
      }
  }
}

std::size_t absorb_face_slivers(RecombineState& s, const std::vector<Candidate>& elements,
                                SliverPolicy policy) {
  const TetTopology& topo = s.topo;
  std::vector<char>& used = s.used;
  const double flat_sj = s.limits.sliver_quality;
  // The policy's test, on all threads, of every free tet (a sliver qualifies or not whatever
  // face it lies on): 1 it qualifies, 2 only where its face is shared, 0 not.
  const auto nt = static_cast<std::ptrdiff_t>(used.size());
  std::vector<std::uint8_t> verdict(used.size(), 0);
#pragma omp parallel for schedule(static, 4096)
  for (std::ptrdiff_t t = 0; t < nt; ++t) {
    if (used[t]) continue;
    if (policy == SliverPolicy::kSharedOrBoundary) {
      const auto& T = topo.mesh().tets[t];
      int on_surface = 0;
      for (int skip = 0; skip < 4; ++skip)
        on_surface +=
            topo.surface_triangle(T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]) >= 0;
      verdict[t] = on_surface < 2 ? 2 : 1;
    } else {
      verdict[t] = tet_quality(topo, static_cast<std::int32_t>(t)) < flat_sj ? 1 : 0;
    }
  }
  std::vector<std::int32_t> candidates;
  for (std::ptrdiff_t t = 0; t < nt; ++t)
    if (verdict[t]) candidates.push_back(static_cast<std::int32_t>(t));
  const TetsByCorners by_corners(topo, candidates);
  // Quad face slot (6 * element + local face) -> the tet on its four corners that qualifies,
  // -1 none, or -2 - tet when it qualifies only if the face is shared. Marking them used is
  // left to the serial pass below, in face order.
  std::vector<std::int32_t> hit(6 * elements.size(), -1);
  // Only a sliver of the element's own solid: on a face between two glued solids (--glue) the
  // other solid's sliver is held by that solid's tets, and taking it would open a hole there.
  const std::vector<std::int32_t>& solid = topo.mesh().tet_solid;
  parallel_for_quad_faces(elements, [&](std::size_t i, int f) {
    const std::int32_t t = by_corners.find(quad_key(elements[i], f));
    if (t >= 0 && solid[t] == solid[elements[i].tets[0]])
      hit[6 * i + f] = verdict[t] == 1 ? t : -2 - t;
  });
  // Every face a tet lies on finds it: how many of the elements have its face.
  std::vector<std::uint8_t> faces(used.size(), 0);
  for (const std::int32_t h : hit)
    if (h <= -2 && faces[-2 - h] < 2) ++faces[-2 - h];
  std::size_t absorbed = 0;
  for (std::int32_t t : hit) {
    if (t == -1) continue;
    if (t <= -2) {
      t = -2 - t;
      if (faces[t] < 2) continue;
    }
    if (used[t]) continue;  // found from the other element on the face
    used[t] = 1;
    s.absorbed.push_back(t);
    ++absorbed;
  }
  s.debug_verify();
  return absorbed;
}

std::size_t release_orphan_slivers(RecombineState& s) {
  const TetTopology& topo = s.topo;
  std::vector<std::int32_t>& absorbed = s.absorbed;
  // How many elements have each sliver's face.
  const TetsByCorners on_face(topo, absorbed);
  std::vector<std::uint8_t> count(s.used.size(), 0);
  parallel_for_quad_faces(s.elements, [&](std::size_t i, int f) {
    const std::int32_t t = on_face.find(quad_key(s.elements[i], f));
    if (t >= 0) {
#pragma omp atomic update
      ++count[t];
    }
  });
  std::size_t released = 0, k = 0;
  for (std::int32_t t : absorbed) {
    const int faces = count[t];
    int on_surface = 0;
    const auto& T = topo.mesh().tets[t];
    for (int skip = 0; skip < 4; ++skip)
      on_surface +=
          topo.surface_triangle(T[(skip + 1) % 4], T[(skip + 2) % 4], T[(skip + 3) % 4]) >= 0;
    const bool keep =
        faces >= 2 ||
        (faces == 1 && (on_surface >= 2 || tet_quality(topo, t) < s.limits.sliver_quality));
    if (keep) {
      absorbed[k++] = t;
    } else {
      s.used[t] = 0;
      ++released;
    }
  }
  absorbed.resize(k);
  s.debug_verify();
  return released;
}

}  // namespace hexfem
