// Slivers on elements' quad faces: a flat tet whose four vertices are the corners of a quad face
// lies between the face's two diagonals. It is absorbed into the element(s) whose bilinear face
// passes through it (it is then used but in no element) and released when that no longer holds.
#pragma once

#include <array>
#include <cstdint>
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

// Tets keyed by their sorted corners (a sliver on a quad face has that face's quad_key), sorted.
using KeyedTet = std::pair<QuadKey, std::int32_t>;
std::vector<KeyedTet> tets_by_corners(const TetTopology& topo,
                                      const std::vector<std::int32_t>& tets);
// Sorted keys (sorted corners) of every quad face of `elements`; a key listed twice is a face
// two elements share.
std::vector<QuadKey> sorted_quad_keys(const std::vector<Candidate>& elements);
bool quad_shared(const std::vector<QuadKey>& keys, const QuadKey& k);

}  // namespace hexfem
