// Hashable, order-independent keys of cell faces, shared by conformity and metrics code.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Sorted node ids of a face; triangles have -1 in slot 0 after sorting (so they sort apart).
using FaceKey = std::array<std::int32_t, 4>;

inline FaceKey face_key(const std::int32_t* cell_ids, const LocalFace& f) {
  FaceKey k{-1, -1, -1, -1};
  for (int i = 0; i < f.n; ++i) k[i] = cell_ids[f.v[i]];
  std::sort(k.begin(), k.end());
  return k;
}

inline FaceKey triangle_key(std::int32_t a, std::int32_t b, std::int32_t c) {
  FaceKey k{-1, a, b, c};
  std::sort(k.begin() + 1, k.end());
  return k;
}

struct CellFaceRef {
  FaceKey key;
  std::int32_t cell;
  std::int8_t local;
  bool operator<(const CellFaceRef& o) const {
    // Element by element: std::array's != goes through memcmp, a hot spot in the sorts.
    for (int i = 0; i < 4; ++i)
      if (key[i] != o.key[i]) return key[i] < o.key[i];
    if (cell != o.cell) return cell < o.cell;
    return local < o.local;
  }
};

// Every face of every cell, sorted by key (equal faces are adjacent). Deterministic.
std::vector<CellFaceRef> sorted_cell_faces(const MixedMesh& mesh);

// True when `key` occurs in `faces` (sorted) for a cell other than `cell`.
bool face_used_by_other_cell(const std::vector<CellFaceRef>& faces, const FaceKey& key,
                             std::int32_t cell);

}  // namespace hexfem
