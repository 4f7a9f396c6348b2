// The one mesh type of hexfem: the mesher produces it; fem, metrics and exporters read it.
// Plain arrays (libigl style): a cell is an index into parallel vectors, with a fixed stride of 8
// node slots so iteration needs no offsets table and no per-element heap objects.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace hexfem {

using Vec3 = std::array<double, 3>;

// Volume element kinds, Gmsh node ordering (see element_topology.hpp for the faces).
enum class CellKind : std::uint8_t { Tet4 = 0, Pyramid5 = 1, Wedge6 = 2, Hex8 = 3 };
inline constexpr int kNumCellKinds = 4;
inline constexpr int kMaxCellNodes = 8;      // corner slots per cell
inline constexpr int kMaxCellEdges = 12;     // mid-edge slots per cell (order 2)
inline constexpr int kMaxElementNodes = 20;  // corners + mid-edge nodes (hex20)

constexpr int num_nodes(CellKind k) {
  switch (k) {
    case CellKind::Tet4:
      return 4;
    case CellKind::Pyramid5:
      return 5;
    case CellKind::Wedge6:
      return 6;
    case CellKind::Hex8:
      return 8;
  }
  return 0;
}

constexpr int num_edges(CellKind k) {
  switch (k) {
    case CellKind::Tet4:
      return 6;
    case CellKind::Pyramid5:
      return 8;
    case CellKind::Wedge6:
      return 9;
    case CellKind::Hex8:
      return 12;
  }
  return 0;
}

// Nodes of the element of this kind and order (order 2: one more node per edge).
constexpr int num_nodes(CellKind k, int order) {
  return order == 2 ? num_nodes(k) + num_edges(k) : num_nodes(k);
}

constexpr const char* kind_name(CellKind k) {
  switch (k) {
    case CellKind::Tet4:
      return "tet4";
    case CellKind::Pyramid5:
      return "pyramid5";
    case CellKind::Wedge6:
      return "wedge6";
    case CellKind::Hex8:
      return "hex8";
  }
  return "?";
}

// The element's name at this order (order 2: tet10, pyramid13, wedge15, hex20).
constexpr const char* kind_name(CellKind k, int order) {
  if (order != 2) return kind_name(k);
  return k == CellKind::Tet4       ? "tet10"
         : k == CellKind::Pyramid5 ? "pyramid13"
         : k == CellKind::Wedge6   ? "wedge15"
                                   : "hex20";
}

struct MixedMesh {
  // Node coordinates, 0-based indices everywhere.
  std::vector<Vec3> nodes;

  // Volume cells. cell_nodes holds kMaxCellNodes slots per cell; unused slots are -1.
  std::vector<CellKind> cell_kind;
  std::vector<std::int32_t> cell_nodes;
  std::vector<std::int32_t> cell_solid;     // CAD solid id (MSH: elementary volume tag)
  std::vector<std::int32_t> cell_physical;  // MSH physical tag, 0 if none

  // Boundary faces (triangles and quads). bface_nodes holds 4 slots per face; a triangle has -1
  // last.
  std::vector<std::int32_t> bface_nodes;
  std::vector<std::int32_t> bface_cad_face;  // CAD face id (MSH: elementary surface tag)
  std::vector<std::int32_t> bface_physical;  // MSH physical tag, 0 if none

  // Interior quad faces that touch triangles instead of an identical quad (non-conformal, NC):
  // the cell and its local face index (element_topology.hpp). Filled by flag_nonconformal_quads().
  std::vector<std::int32_t> nc_cell;
  std::vector<std::int8_t> nc_local_face;

  // Element order: 1 (corners only) or 2. At order 2 every cell has a node at the middle of each
  // edge (placed on the CAD geometry on the boundary), appended to `nodes` after the corners;
  // cell_edge_nodes holds kMaxCellEdges slots per cell in the edge order of element_topology.hpp
  // (Gmsh's), -1 past the kind's edge count, and bface_edge_nodes 4 slots per boundary face:
  // the node on edge (v[i], v[i+1]) at slot i, -1 for a triangle's fourth. Both are empty at
  // order 1, so order-1 code that reads only the corners (cell(), bface()) stays valid.
  int order = 1;
  std::vector<std::int32_t> cell_edge_nodes;
  std::vector<std::int32_t> bface_edge_nodes;

  // Physical group names as read from or written to MSH: (dimension, tag) -> name.
  std::map<std::pair<int, int>, std::string> physical_names;

  // The unit of the coordinates when known: "mm" (hexfem meshes CAD parts in millimetres) or
  // "m"; empty for a mesh file that does not say. MSH files written by hexfem record it, so that
  // a solver reading one back needs no --units.
  std::string length_unit;

  std::size_t num_cells() const { return cell_kind.size(); }
  std::size_t num_bfaces() const { return bface_cad_face.size(); }
  const std::int32_t* cell(std::size_t c) const { return &cell_nodes[kMaxCellNodes * c]; }
  const std::int32_t* bface(std::size_t f) const { return &bface_nodes[4 * f]; }
  bool bface_is_quad(std::size_t f) const { return bface_nodes[4 * f + 3] >= 0; }

  const std::int32_t* cell_edges(std::size_t c) const {
    return &cell_edge_nodes[kMaxCellEdges * c];
  }
  // Every node of cell c in the element's order (corners, then mid-edge nodes at order 2) into
  // `out` (kMaxElementNodes slots); returns the count.
  int element_nodes(std::size_t c, std::int32_t* out) const {
    const int nc = num_nodes(cell_kind[c]);
    for (int i = 0; i < nc; ++i) out[i] = cell_nodes[kMaxCellNodes * c + i];
    if (order != 2) return nc;
    const int ne = num_edges(cell_kind[c]);
    for (int i = 0; i < ne; ++i) out[nc + i] = cell_edge_nodes[kMaxCellEdges * c + i];
    return nc + ne;
  }

  // The nodes of boundary face f in Gmsh's tri3/quad4 (order 1) or tri6/quad8 (order 2) order:
  // corners, then the mid-edge nodes of edges (v0,v1), (v1,v2), ... Returns the count.
  int bface_element_nodes(std::size_t f, std::int32_t* out) const {
    const int nc = bface_is_quad(f) ? 4 : 3;
    for (int i = 0; i < nc; ++i) out[i] = bface_nodes[4 * f + i];
    if (order != 2) return nc;
    for (int i = 0; i < nc; ++i) out[nc + i] = bface_edge_nodes[4 * f + i];
    return 2 * nc;
  }

  // Appends a cell; `ids` holds num_nodes(kind) node indices.
  void add_cell(CellKind kind, const std::int32_t* ids, std::int32_t solid = 1,
                std::int32_t physical = 0) {
    cell_kind.push_back(kind);
    const int n = num_nodes(kind);
    for (int i = 0; i < kMaxCellNodes; ++i) cell_nodes.push_back(i < n ? ids[i] : -1);
    cell_solid.push_back(solid);
    cell_physical.push_back(physical);
  }
  void add_cell(CellKind kind, std::initializer_list<std::int32_t> ids, std::int32_t solid = 1,
                std::int32_t physical = 0) {
    add_cell(kind, ids.begin(), solid, physical);
  }
  // Appends a boundary triangle (d < 0) or quad.
  void add_bface(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d,
                 std::int32_t cad_face, std::int32_t physical = 0) {
    bface_nodes.insert(bface_nodes.end(), {a, b, c, d});
    bface_cad_face.push_back(cad_face);
    bface_physical.push_back(physical);
  }
};

}  // namespace hexfem
