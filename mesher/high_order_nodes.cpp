#include "mesher/high_order_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quad8.hpp"

namespace hexfem {

namespace {

std::uint64_t edge_key(std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

Vec3 midpoint(const Vec3& a, const Vec3& b) {
  return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                   (a[2] - b[2]) * (a[2] - b[2]));
}

struct BoundaryEdge {
  std::int32_t a, b, node;
  int face1, face2;
};

}  // namespace

void add_mid_edge_nodes(MixedMesh& mesh, const MidEdgeProjector& project, Order2Report* report) {
  if (mesh.order != 1) throw Error("add_mid_edge_nodes: the mesh is already of order 2");
  Order2Report r;
  std::unordered_map<std::uint64_t, std::int32_t> node_of_edge;
  node_of_edge.reserve(mesh.num_cells() * 3);
  const auto node_on = [&](std::int32_t a, std::int32_t b) {
    const auto [it, added] =
        node_of_edge.emplace(edge_key(a, b), static_cast<std::int32_t>(mesh.nodes.size()));
    if (added) mesh.nodes.push_back(midpoint(mesh.nodes[a], mesh.nodes[b]));
    return it->second;
  };
  mesh.cell_edge_nodes.assign(kMaxCellEdges * mesh.num_cells(), -1);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellKind kind = mesh.cell_kind[c];
    const std::int32_t* v = mesh.cell(c);
    for (int e = 0; e < num_edges(kind); ++e)
      mesh.cell_edge_nodes[kMaxCellEdges * c + e] =
          node_on(v[edges_of(kind)[e][0]], v[edges_of(kind)[e][1]]);
  }
  r.edge_nodes = static_cast<long>(node_of_edge.size());

  // Boundary edges with the CAD faces on either side.
  std::unordered_map<std::int32_t, std::size_t> boundary_index;
  std::vector<BoundaryEdge> boundary;
  mesh.bface_edge_nodes.assign(4 * mesh.num_bfaces(), -1);
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    const std::int32_t* v = mesh.bface(f);
    const int n = mesh.bface_is_quad(f) ? 4 : 3;
    for (int i = 0; i < n; ++i) {
      const std::int32_t a = v[i], b = v[(i + 1) % n], node = node_on(a, b);
      mesh.bface_edge_nodes[4 * f + i] = node;
      const int face = mesh.bface_cad_face[f];
      const auto [it, added] = boundary_index.emplace(node, boundary.size());
      if (added)
        boundary.push_back({a, b, node, face, face});
      else if (boundary[it->second].face1 != face)
        boundary[it->second].face2 = face;
    }
  }
  r.boundary_nodes = static_cast<long>(boundary.size());
  if (project) {
    for (const BoundaryEdge& e : boundary) {
      const Vec3 &a = mesh.nodes[e.a], &b = mesh.nodes[e.b];
      const Vec3 p = project(a, b, e.face1, e.face2);
      const double len = distance(a, b), off = distance(p, midpoint(a, b));
      if (!(off <= 0.5 * len)) {  // a jump to another branch of the surface, or NaN
        ++r.projection_refused;
        continue;
      }
      mesh.nodes[e.node] = p;
      if (off > 1e-12 * len) ++r.curved_nodes;
      r.max_offset = std::max(r.max_offset, off / len);
    }
  }
  mesh.order = 2;
  if (report) *report = r;
}

void straighten_invalid_cells(MixedMesh& mesh, const CellJacobianRatio& ratio, double min_ratio,
                              Order2Report* report) {
  // The straight position of every mid-edge node, from its cell's corners.
  std::vector<Vec3> straight(mesh.nodes.size());
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellKind kind = mesh.cell_kind[c];
    for (int e = 0; e < num_edges(kind); ++e) {
      const std::int32_t m = mesh.cell_edges(c)[e];
      straight[m] = midpoint(mesh.nodes[mesh.cell(c)[edges_of(kind)[e][0]]],
                             mesh.nodes[mesh.cell(c)[edges_of(kind)[e][1]]]);
    }
  }
  long cells = 0, nodes = 0;
  // Straightening an edge also flattens the neighbours' curve, which may (rarely) spoil one of
  // them: a few passes.
  for (int pass = 0, changed = 1; pass < 4 && changed; ++pass) {
    changed = 0;
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      const double before = ratio(mesh, c);
      if (before >= min_ratio) continue;
      std::vector<std::pair<std::int32_t, Vec3>> moved;
      for (int e = 0; e < num_edges(mesh.cell_kind[c]); ++e) {
        const std::int32_t m = mesh.cell_edges(c)[e];
        if (mesh.nodes[m] == straight[m]) continue;
        moved.push_back({m, mesh.nodes[m]});
        mesh.nodes[m] = straight[m];
      }
      if (moved.empty()) continue;
      if (ratio(mesh, c) <= before) {  // straight is no better: keep the geometry
        for (const auto& [m, x] : moved) mesh.nodes[m] = x;
        continue;
      }
      ++cells;
      ++changed;
      nodes += static_cast<long>(moved.size());
    }
  }
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    if (!(ratio(mesh, c) > 0))
      throw Error("order 2: cell " + std::to_string(c + 1) + " (" +
                  kind_name(mesh.cell_kind[c], 2) +
                  ") has a non-positive Jacobian even with straight edges");
  if (report) {
    report->straightened_cells += cells;
    report->straightened_nodes += nodes;
  }
}

void place_hanging_nodes_on_quads(MixedMesh& mesh, const CellJacobianRatio& ratio, double min_ratio,
                                  Order2Report* report) {
  if (mesh.order != 2 || mesh.nc_cell.empty()) return;
  std::unordered_map<std::int32_t, std::vector<std::int32_t>> cells_of;  // mid-edge node -> cells
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    for (int e = 0; e < num_edges(mesh.cell_kind[c]); ++e)
      cells_of[mesh.cell_edges(c)[e]].push_back(static_cast<std::int32_t>(c));
  // The side nodes of the NC quads are masters of ties and stay put.
  const std::vector<NcQuad8> quads = nc_quad8_faces(mesh);
  std::vector<std::uint8_t> side(mesh.nodes.size(), 0);
  for (const NcQuad8& q : quads)
    for (int i = 4; i < 8; ++i) side[static_cast<std::size_t>(q.nodes[i])] = 1;
  std::vector<std::uint8_t> done(mesh.nodes.size(), 0);
  long placed = 0, kept = 0;
  for (const NcQuad8& q : quads)
    for (const std::int32_t h : q.diagonal) {
      if (h < 0 || done[h] || side[h]) continue;
      done[h] = 1;
      const Quad8Nearest near = quad8_nearest(mesh, q.nodes.data(), mesh.nodes[h]);
      if (std::abs(near.x) >= 0.999 || std::abs(near.y) >= 0.999) continue;  // not over the face
      if (near.distance <= 1e-9 * near.size) continue;                       // on it already
      const std::vector<std::int32_t>& around = cells_of[h];
      std::vector<double> before(around.size());
      for (std::size_t i = 0; i < around.size(); ++i)
        before[i] = ratio(mesh, static_cast<std::size_t>(around[i]));
      const Vec3 old = mesh.nodes[h];
      mesh.nodes[h] = near.at;
      bool ok = true;
      for (std::size_t i = 0; i < around.size() && ok; ++i)
        ok = ratio(mesh, static_cast<std::size_t>(around[i])) >= std::min(min_ratio, before[i]);
      if (ok) {
        ++placed;
      } else {
        mesh.nodes[h] = old;
        ++kept;
      }
    }
  if (report) {
    report->hanging_placed += placed;
    report->hanging_kept += kept;
  }
}

}  // namespace hexfem
