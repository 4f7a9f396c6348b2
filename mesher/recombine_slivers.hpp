// Slivers on elements' quad faces: a flat tet whose four vertices are the corners of a quad face
// lies between the face's two diagonals. It is absorbed into the element(s) whose bilinear face
// passes through it (it is then used but in no element) and released when that no longer holds.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "mesher/recombine_state.hpp"

namespace hexfem {

// Free tets whose four vertices are the corners of a quad face of one of `elements`: slivers
// between the face's two diagonals, which fills_element leaves out. Such a sliver belongs to the
// element(s) whose bilinear face cuts through it:
//  - kSharedOrBoundary: the face is shared by two elements, or the sliver's other two faces are
//    surface triangles (the element's tets split the face along one diagonal, the surface along
//    the other): the element's quad face is then the boundary face.
//  - kFlat: any other sliver on a quad face whose min scaled Jacobian is below
//    s.limits.sliver_quality (a flat tet against tets: the bilinear face passes through it; left
//    alone it is a zero-volume cell).
// Absorbed slivers are marked used and appended to s.absorbed; returns how many. `on` is
// s.elements or a part of it.
enum class SliverPolicy { kSharedOrBoundary, kFlat };
std::size_t absorb_face_slivers(RecombineState& s, const std::vector<Candidate>& on,
                                SliverPolicy policy);

// After elements were removed: every absorbed sliver that no longer qualifies under
// absorb_face_slivers' rules (shared by two elements, under a boundary face, or below
// s.limits.sliver_quality on one element's face) is freed and dropped from s.absorbed. Returns
// how many.
std::size_t release_orphan_slivers(RecombineState& s);

// Tets found by their four corners, asked from quad faces (a sliver on a quad face has the
// face's quad_key): a few hundred thousand tets against millions of faces. A bit per hash value
// (2 MB, a few percent of false hits) turns most faces away before the map's table is read.
class TetsByCorners {
 public:
  TetsByCorners(const TetTopology& topo, const std::vector<std::int32_t>& tets);
  // The tet whose sorted corners are k, or -1 (no two tets have the same four vertices).
  std::int32_t find(const QuadKey& k) const {
    const std::uint64_t b = Hash{}(k) >> (64 - kFilterBits);
    if (!(filter_[b >> 6] >> (b & 63) & 1)) return -1;
    const std::int32_t* t = map_.find(k);
    return t ? *t : -1;
  }

 private:
  struct Hash {
    std::size_t operator()(const QuadKey& k) const {
      std::uint64_t h = static_cast<std::uint32_t>(k[0]);
      for (int i = 1; i < 4; ++i) h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(k[i]);
      return static_cast<std::size_t>(mix64(h));
    }
  };
  static constexpr int kFilterBits = 24;
  OpenHashMap<QuadKey, std::int32_t, Hash> map_;
  std::vector<std::uint64_t> filter_;
};

// visit(element, local face) for every quad face of `elements`, on all threads.
void parallel_for_quad_faces(const std::vector<Candidate>& elements,
                             const std::function<void(std::size_t, int)>& visit);

// Every quad face of a list of elements, filed under its lowest corner (a few faces per vertex),
// and for each face the other element's face with the same corners: which faces two elements
// share, read in a slot, or for any four corners in a short scan instead of a search of all
// faces. A slot is 6 * element + local face. Built on all threads, each filing the faces of its
// own range of vertices in element order, so nothing depends on the threads.
class QuadFaces {
 public:
  // Vertices are below num_vertices.
  QuadFaces(const std::vector<Candidate>& elements, std::size_t num_vertices);
  // The slot of the other face with the same corners as quad face `slot` when exactly two
  // elements have it; kAlone when no other element has it; kMany when more do.
  static constexpr std::int32_t kAlone = -1, kMany = -2;
  std::int32_t match(std::size_t slot) const { return match_[slot]; }
  bool shared(std::size_t slot) const { return match_[slot] != kAlone; }

 private:
  struct Face {
    std::int32_t v[3];  // the other three corners, sorted
    std::int32_t slot;
  };
  std::vector<std::int32_t> off_;
  std::vector<Face> face_;
  std::vector<std::int32_t> match_;
};

}  // namespace hexfem
