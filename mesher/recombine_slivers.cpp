#include "mesher/recombine_slivers.hpp"

#include <algorithm>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/parallel_sort.hpp"

namespace hexfem {

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
  parallel_sort(keys);
  return keys;
}

bool quad_shared(const std::vector<QuadKey>& keys, const QuadKey& k) {
  const auto range = std::equal_range(keys.begin(), keys.end(), k);
  return range.second - range.first >= 2;
}

std::size_t absorb_face_slivers(RecombineState& s, const std::vector<Candidate>& elements,
                                SliverPolicy policy) {
  const TetTopology& topo = s.topo;
  std::vector<char>& used = s.used;
  const double flat_sj = s.limits.sliver_quality;
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
  std::size_t absorbed = 0;
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
      s.absorbed.push_back(t);
      ++absorbed;
    }
  }
  s.debug_verify();
  return absorbed;
}

std::size_t release_orphan_slivers(RecombineState& s) {
  const TetTopology& topo = s.topo;
  std::vector<std::int32_t>& absorbed = s.absorbed;
  const std::vector<QuadKey> quads = sorted_quad_keys(s.elements);
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
