// Local faces and corner edges of each cell kind, in Gmsh's node ordering.
// Faces are listed with outward normals (right-hand rule) for a positively oriented cell.
#pragma once

#include <array>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct LocalFace {
  int n;                 // 3 or 4
  std::array<int, 4> v;  // local node indices, outward orientation; v[3] = -1 for triangles
};

struct CellFaces {
  int count;
  std::array<LocalFace, 6> face;
};

inline constexpr CellFaces kCellFaces[kNumCellKinds] = {
    // Tet4
    {4, {{{3, {0, 2, 1, -1}}, {3, {0, 1, 3, -1}}, {3, {0, 3, 2, -1}}, {3, {1, 2, 3, -1}}}}},
    // Pyramid5
    {5,
     {{{4, {0, 3, 2, 1}},
       {3, {0, 1, 4, -1}},
       {3, {1, 2, 4, -1}},
       {3, {2, 3, 4, -1}},
       {3, {3, 0, 4, -1}}}}},
    // Wedge6
    {5,
     {{{3, {0, 2, 1, -1}},
       {3, {3, 4, 5, -1}},
       {4, {0, 1, 4, 3}},
       {4, {0, 3, 5, 2}},
       {4, {1, 2, 5, 4}}}}},
    // Hex8
    {6,
     {{{4, {0, 3, 2, 1}},
       {4, {0, 1, 5, 4}},
       {4, {0, 4, 7, 3}},
       {4, {1, 2, 6, 5}},
       {4, {2, 3, 7, 6}},
       {4, {4, 5, 6, 7}}}}}};

// Faces of a kind; a reference into a static table (safe to keep).
constexpr const CellFaces& faces_of(CellKind k) {
  return kCellFaces[static_cast<int>(k)];
}

// Edges of each kind in the order of the order-2 element's mid-edge nodes (Gmsh's tet10,
// pyramid13, prism15 and hex20): mid-edge node k of a cell lies on edge kCellEdges[kind][k].
inline constexpr std::array<std::array<int, 2>, kMaxCellEdges> kCellEdges[kNumCellKinds] = {
    // Tet4 -> tet10
    {{{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}}},
    // Pyramid5 -> pyramid13
    {{{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 4}, {2, 3}, {2, 4}, {3, 4}}},
    // Wedge6 -> prism15
    {{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 4}, {2, 5}, {3, 4}, {3, 5}, {4, 5}}},
    // Hex8 -> hex20
    {{{0, 1},
      {0, 3},
      {0, 4},
      {1, 2},
      {1, 5},
      {2, 3},
      {2, 6},
      {3, 7},
      {4, 5},
      {4, 7},
      {5, 6},
      {6, 7}}}};

constexpr const std::array<std::array<int, 2>, kMaxCellEdges>& edges_of(CellKind k) {
  return kCellEdges[static_cast<int>(k)];
}

// The local edge joining corners a and b of a kind, -1 if none.
constexpr int local_edge(CellKind k, int a, int b) {
  for (int e = 0; e < num_edges(k); ++e) {
    const auto& ed = edges_of(k)[e];
    if ((ed[0] == a && ed[1] == b) || (ed[0] == b && ed[1] == a)) return e;
  }
  return -1;
}

// For each corner of a cell: the corners joined to it by an edge, ordered so that
// (e1, e2, e3) = (v[a]-v[i], v[b]-v[i], v[c]-v[i]) is right-handed on a positive cell.
// The pyramid apex has four edges; its corner is handled specially by quality code
// (it is not an "all-edges" corner), so only the four base corners are listed here.
struct CornerEdges {
  int count;
  std::array<std::array<int, 4>, 8> corner;  // {corner, a, b, c}
};

constexpr CornerEdges corners_of(CellKind k) {
  switch (k) {
    case CellKind::Tet4:
      return {4, {{{0, 1, 2, 3}, {1, 2, 0, 3}, {2, 0, 1, 3}, {3, 0, 2, 1}}}};
    case CellKind::Pyramid5:
      return {4, {{{0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}}}};
    case CellKind::Wedge6:
      return {
          6,
          {{{0, 1, 2, 3}, {1, 2, 0, 4}, {2, 0, 1, 5}, {3, 5, 4, 0}, {4, 3, 5, 1}, {5, 4, 3, 2}}}};
    case CellKind::Hex8:
      return {8,
              {{{0, 1, 3, 4},
                {1, 2, 0, 5},
                {2, 3, 1, 6},
                {3, 0, 2, 7},
                {4, 7, 5, 0},
                {5, 4, 6, 1},
                {6, 5, 7, 2},
                {7, 6, 4, 3}}}};
  }
  return {0, {}};
}

}  // namespace hexfem
