#include "mesher/high_order_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/parallel.hpp"
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

// ratio(mesh, c) of every cell, on all threads (the ratio only reads the mesh).
std::vector<double> ratios_of_all_cells(const MixedMesh& mesh, const CellJacobianRatio& ratio) {
  std::vector<double> q(mesh.num_cells());
  const auto n = static_cast<std::ptrdiff_t>(q.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t c = 0; c < n; ++c) q[c] = ratio(mesh, static_cast<std::size_t>(c));
  return q;
}

// q[c] = ratio(mesh, c) again for every cell with a mid-edge node flagged in `moved`, on all
// threads: q is then every cell's ratio, if it was before those nodes moved.
void refresh_ratios(const MixedMesh& mesh, const CellJacobianRatio& ratio,
                    const std::vector<char>& moved, std::vector<double>& q) {
  const auto n = static_cast<std::ptrdiff_t>(q.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t c = 0; c < n; ++c) {
    const auto cell = static_cast<std::size_t>(c);
    bool stale = false;
    for (int e = 0; e < num_edges(mesh.cell_kind[cell]) && !stale; ++e)
      stale = moved[mesh.cell_edges(cell)[e]] != 0;
    if (stale) q[cell] = ratio(mesh, cell);
  }
}

// The cells around each mid-edge node, in increasing order (CSR: those of node m are
// around[start[m]] to around[start[m + 1] - 1]).
void cells_around_edge_nodes(const MixedMesh& mesh, std::vector<std::int32_t>& start,
                             std::vector<std::int32_t>& around) {
  std::size_t slots = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) slots += num_edges(mesh.cell_kind[c]);
  around.resize(slots);
  parallel_bucket_items(
      mesh.num_cells(), mesh.nodes.size(),
      [&](std::size_t c, auto&& f) {
        for (int e = 0; e < num_edges(mesh.cell_kind[c]); ++e) f(mesh.cell_edges(c)[e]);
      },
      start,
      [&](std::size_t i, std::size_t c, std::int32_t) {
        around[i] = static_cast<std::int32_t>(c);
      });
}

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
    // Each projection on its own (the nodes are distinct and only the edge's corners are read):
    // on all threads, the counts joined after.
    const auto n = static_cast<std::ptrdiff_t>(boundary.size());
    long refused = 0, curved = 0;
    double max_offset = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : refused, curved) \
    reduction(max : max_offset)
    for (std::ptrdiff_t i = 0; i < n; ++i) {
      const BoundaryEdge& e = boundary[i];
      const Vec3 &a = mesh.nodes[e.a], &b = mesh.nodes[e.b];
      const Vec3 p = project(a, b, e.face1, e.face2);
      const double len = distance(a, b), off = distance(p, midpoint(a, b));
      if (!(off <= 0.5 * len)) {  // a jump to another branch of the surface, or NaN
        ++refused;
        continue;
      }
      mesh.nodes[e.node] = p;
      if (off > 1e-12 * len) ++curved;
      max_offset = std::max(max_offset, off / len);
    }
    r.projection_refused += refused;
    r.curved_nodes += curved;
    r.max_offset = std::max(r.max_offset, max_offset);
  }
  mesh.order = 2;
  if (report) *report = r;
}

void bend_interior_nodes(MixedMesh& mesh, const CellJacobianRatio& ratio,
                         const CellJacobianRatio& search_ratio, double min_ratio,
                         Order2Report* report, std::vector<double>* ratios) {
  if (mesh.order != 2) return;
  const std::size_t ncells = mesh.num_cells();
  std::vector<double> q = ratios_of_all_cells(mesh, ratio);
  // q stays every cell's ratio: a bend kept updates its region (every cell around a moved
  // node), one undone puts the nodes back exactly.
  std::vector<std::size_t> bad;
  for (std::size_t c = 0; c < ncells; ++c)
    if (q[c] < min_ratio) bad.push_back(c);
  if (bad.empty()) {
    if (ratios) *ratios = std::move(q);
    return;
  }
  std::vector<std::uint8_t> on_boundary(mesh.nodes.size(), 0);
  for (const std::int32_t m : mesh.bface_edge_nodes)
    if (m >= 0) on_boundary[static_cast<std::size_t>(m)] = 1;
  std::vector<std::int32_t> start, around;
  cells_around_edge_nodes(mesh, start, around);
  // Enough for nine in ten of the cells mended on ANC101 at h = 17; a cell that needs more is
  // left to straightening.
  constexpr int kMaxEvaluations = 1500;
  constexpr int kBulgeScan = 16;  // shifts along the bulge tried, up to half an edge
  // The search aims at a comfortable ratio, and accepts anything from min_ratio up.
  const double target = std::max(2 * min_ratio, 0.05);
  long cells = 0, nodes = 0;
  for (const std::size_t c : bad) {
    if (q[c] >= min_ratio) continue;  // mended while bending a neighbour
    const CellKind kind = mesh.cell_kind[c];
    std::vector<std::int32_t> free;
    double len = 0;
    Vec3 bulge{0, 0, 0};  // the mean offset of the cell's curved boundary nodes
    for (int e = 0; e < num_edges(kind); ++e) {
      const std::int32_t m = mesh.cell_edges(c)[e];
      const Vec3 &a = mesh.nodes[mesh.cell(c)[edges_of(kind)[e][0]]],
                 &b = mesh.nodes[mesh.cell(c)[edges_of(kind)[e][1]]];
      len += distance(a, b);
      if (on_boundary[m]) {
        for (int k = 0; k < 3; ++k) bulge[k] += mesh.nodes[m][k] - (a[k] + b[k]) / 2;
      } else if (std::find(free.begin(), free.end(), m) == free.end()) {
        free.push_back(m);
      }
    }
    if (free.empty()) continue;
    len /= num_edges(kind);
    const double bulge_len = distance(bulge, Vec3{0, 0, 0});
    std::vector<std::int32_t> region;
    for (const std::int32_t m : free)
      region.insert(region.end(), around.begin() + start[m], around.begin() + start[m + 1]);
    std::sort(region.begin(), region.end());
    region.erase(std::unique(region.begin(), region.end()), region.end());
    const auto at = [&](std::int32_t r) {  // r's place in the (sorted) region
      return static_cast<std::size_t>(std::lower_bound(region.begin(), region.end(), r) -
                                      region.begin());
    };
    std::vector<double> before(region.size()), qs(region.size());
    for (std::size_t i = 0; i < region.size(); ++i) {
      before[i] = q[region[i]];
      qs[i] = search_ratio(mesh, static_cast<std::size_t>(region[i]));
    }
    std::vector<Vec3> start_at(free.size());
    for (std::size_t i = 0; i < free.size(); ++i) start_at[i] = mesh.nodes[free[i]];
    const auto worst_except = [&](std::int32_t m) {  // worst ratio of the region off node m
      double w = 2;
      for (std::size_t i = 0; i < region.size(); ++i)
        if (std::find(around.begin() + start[m], around.begin() + start[m + 1], region[i]) ==
            around.begin() + start[m + 1])
          w = std::min(w, qs[i]);
      return w;
    };
    double best = *std::min_element(qs.begin(), qs.end());
    int evaluations = 0;
    // First all the free nodes together along the bulge, scanned: several corners of the cell
    // are often inverted at once, no single node can raise them all, and the window of valid
    // shifts can be narrow (a tenth of the edge).
    if (bulge_len > 0) {
      int best_k = 0;
      std::vector<double> all(region.size());
      for (int k = 1; k <= kBulgeScan; ++k) {
        const double t = k * 0.5 * len / kBulgeScan / bulge_len;
        for (std::size_t j = 0; j < free.size(); ++j)
          for (int i = 0; i < 3; ++i) mesh.nodes[free[j]][i] = start_at[j][i] + t * bulge[i];
        double w = 2;
        for (std::size_t i = 0; i < region.size(); ++i)
          w = std::min(w, all[i] = search_ratio(mesh, static_cast<std::size_t>(region[i])));
        evaluations += static_cast<int>(region.size());
        if (w > best * (1 + 1e-9) + 1e-12) {
          best = w;
          best_k = k;
          qs = all;
        }
      }
      const double t = best_k * 0.5 * len / kBulgeScan / bulge_len;
      for (std::size_t j = 0; j < free.size(); ++j)
        for (int i = 0; i < 3; ++i) mesh.nodes[free[j]][i] = start_at[j][i] + t * bulge[i];
    }
    std::vector<double> trial;
    for (double step = 0.1 * len;
         step > 1e-3 * len && best < target && evaluations < kMaxEvaluations;) {
      bool improved = false;
      for (const std::int32_t m : free) {
        const double others = worst_except(m);
        if (others <= best) continue;  // node m cannot raise the worst cell
        const std::size_t k0 = static_cast<std::size_t>(start[m]),
                          k1 = static_cast<std::size_t>(start[m + 1]);
        for (int d = 0; d < 6; ++d) {
          const Vec3 old = mesh.nodes[m];
          mesh.nodes[m][d / 2] += (d % 2 ? -step : step);
          trial.assign(k1 - k0, 0);
          double w = others;
          for (std::size_t k = k0; k < k1; ++k)
            w = std::min(w,
                         trial[k - k0] = search_ratio(mesh, static_cast<std::size_t>(around[k])));
          evaluations += static_cast<int>(k1 - k0);
          if (w > best * (1 + 1e-9) + 1e-12) {
            for (std::size_t k = k0; k < k1; ++k) qs[at(around[k])] = trial[k - k0];
            best = w;
            improved = true;
            break;
          }
          mesh.nodes[m] = old;
        }
      }
      if (!improved) step /= 2;
    }
    // The search's ratio may see fewer points: the full one decides.
    std::vector<double> after(region.size());
    bool ok = true;
    for (std::size_t i = 0; i < region.size() && ok; ++i) {
      after[i] = ratio(mesh, static_cast<std::size_t>(region[i]));
      ok = after[i] >=
           (region[i] == static_cast<std::int32_t>(c) ? min_ratio : std::min(min_ratio, before[i]));
    }
    if (!ok) {  // undo: straightening will deal with it
      for (std::size_t i = 0; i < free.size(); ++i) mesh.nodes[free[i]] = start_at[i];
      continue;
    }
    for (std::size_t i = 0; i < region.size(); ++i) q[region[i]] = after[i];
    ++cells;
    for (std::size_t i = 0; i < free.size(); ++i) nodes += mesh.nodes[free[i]] != start_at[i];
  }
  if (report) {
    report->bent_cells += cells;
    report->bent_nodes += nodes;
  }
  if (ratios) *ratios = std::move(q);
}

void straighten_invalid_cells(MixedMesh& mesh, const CellJacobianRatio& ratio, double min_ratio,
                              Order2Report* report, std::vector<double>* ratios) {
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
  // Each pass reads every cell's ratio, found on all threads first; a cell whose mid-edge node
  // an earlier cell of the pass moved is measured again when its turn comes.
  // The ratios at a pass's start: those the caller gave, or all found once; then those of the
  // cells whose nodes the previous pass moved found again.
  std::vector<char> moved_in_pass(mesh.nodes.size());
  std::vector<double> at_start;
  if (ratios && ratios->size() == mesh.num_cells())
    at_start = std::move(*ratios);
  else
    at_start = ratios_of_all_cells(mesh, ratio);
  for (int pass = 0, changed = 1; pass < 4 && changed; ++pass) {
    changed = 0;
    if (pass > 0) refresh_ratios(mesh, ratio, moved_in_pass, at_start);
    std::fill(moved_in_pass.begin(), moved_in_pass.end(), 0);
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      bool stale = false;
      for (int e = 0; e < num_edges(mesh.cell_kind[c]); ++e)
        stale = stale || moved_in_pass[mesh.cell_edges(c)[e]];
      const double before = stale ? ratio(mesh, c) : at_start[c];
      if (before >= min_ratio) continue;
      std::vector<std::pair<std::int32_t, Vec3>> moved;
      for (int e = 0; e < num_edges(mesh.cell_kind[c]); ++e) {
        const std::int32_t m = mesh.cell_edges(c)[e];
        if (mesh.nodes[m] == straight[m]) continue;
        moved.push_back({m, mesh.nodes[m]});
      }
      if (moved.empty()) continue;
      // As little of the curve taken back as makes the cell valid, in tenths: on the coarse
      // torus a hex with two boundary faces at a flat angle folds at their shared edge, and
      // a tenth less bulge mends it where the straight cell left a flat spot (order2.md).
      double after = before;
      for (const double keep : {0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0}) {
        for (const auto& [m, x] : moved)
          for (int k = 0; k < 3; ++k)
            mesh.nodes[m][k] = straight[m][k] + keep * (x[k] - straight[m][k]);
        if ((after = ratio(mesh, c)) >= min_ratio) break;
      }
      if (after <= before) {  // straight is no better: keep the geometry
        for (const auto& [m, x] : moved) mesh.nodes[m] = x;
        continue;
      }
      ++cells;
      ++changed;
      nodes += static_cast<long>(moved.size());
      for (const auto& mx : moved) moved_in_pass[mx.first] = 1;
    }
  }
  refresh_ratios(mesh, ratio, moved_in_pass, at_start);
  const std::vector<double>& final_ratio = at_start;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    if (!(final_ratio[c] > 0))
      throw Error("order 2: cell " + std::to_string(c + 1) + " (" +
                  kind_name(mesh.cell_kind[c], 2) +
                  ") has a non-positive Jacobian even with straight edges");
  if (report) {
    report->straightened_cells += cells;
    report->straightened_nodes += nodes;
  }
  if (ratios) *ratios = std::move(at_start);
}

void place_hanging_nodes_on_quads(MixedMesh& mesh, const CellJacobianRatio& ratio, double min_ratio,
                                  Order2Report* report, std::vector<double>* ratios) {
  const bool known = ratios && ratios->size() == mesh.num_cells();
  if (mesh.order != 2 || mesh.nc_cell.empty()) return;
  std::vector<std::int32_t> start, around_all;
  cells_around_edge_nodes(mesh, start, around_all);
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
      const std::span<const std::int32_t> around(around_all.data() + start[h],
                                                 around_all.data() + start[h + 1]);
      std::vector<double> before(around.size()), after(around.size());
      for (std::size_t i = 0; i < around.size(); ++i)
        before[i] = known ? (*ratios)[around[i]] : ratio(mesh, static_cast<std::size_t>(around[i]));
      const Vec3 old = mesh.nodes[h];
      mesh.nodes[h] = near.at;
      bool ok = true;
      for (std::size_t i = 0; i < around.size() && ok; ++i)
        ok = (after[i] = ratio(mesh, static_cast<std::size_t>(around[i]))) >=
             std::min(min_ratio, before[i]);
      if (ok) {
        ++placed;
        if (known)
          for (std::size_t i = 0; i < around.size(); ++i) (*ratios)[around[i]] = after[i];
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
