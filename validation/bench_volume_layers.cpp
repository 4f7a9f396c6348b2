// Study: where the non-hex elements of a hex-dominant mesh lie. Meshes a CAD part (surface +
// volume), then bins every cell's volume by kind against
//   - its depth: distance from its centroid to the boundary, in units of the local size h;
//   - the wall thickness through it (near boundary distance + ray to the far side, in h);
//   - its distance to the nearest CAD edge (in h), convex or concave;
//   - whether the nearest boundary face is planar or curved;
// and reports how regular the interior point lattice is (per interior vertex: how many of the
// six points x +- h d_i of its frame exist within 0.25 h) at each depth.
//   bench_volume_layers <part> <h> [--k K] [--min-quality Q] [--max-volume-gap G]
//                       [--max-face-twist T] [--min-pyramid-quality P] [--nearest-frame]
//                       [--quick] [--out mesh.msh]
#include <array>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/frame_field_3d.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/surface_pipeline.hpp"
#include "mesher/volume_pipeline.hpp"

using namespace hexfem;

namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using RPoint = bg::model::point<double, 3, bg::cs::cartesian>;
using RValue = std::pair<RPoint, std::int32_t>;
using RTree = bgi::rtree<RValue, bgi::rstar<16>>;

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
Vec3 unit(Vec3 a) {
  const double n = norm(a);
  for (double& x : a) x /= n;
  return a;
}
RPoint rp(const Vec3& p) {
  return RPoint(p[0], p[1], p[2]);
}

// Volume per cell kind in one bin.
struct Bin {
  std::array<double, kNumCellKinds> vol{};
  std::array<std::size_t, kNumCellKinds> count{};
  double total() const { return vol[0] + vol[1] + vol[2] + vol[3]; }
};

struct Table {
  std::string title;
  std::vector<std::string> labels;
  std::vector<Bin> bins;
  Table(std::string t, std::vector<std::string> l)
      : title(std::move(t)), labels(std::move(l)), bins(labels.size()) {}
  void add(std::size_t b, CellKind k, double v) {
    bins[b].vol[static_cast<int>(k)] += v;
    ++bins[b].count[static_cast<int>(k)];
  }
  void print(double total_vol) const {
    double nonhex = 0;
    for (const Bin& b : bins) nonhex += b.total() - b.vol[static_cast<int>(CellKind::Hex8)];
    std::printf("\n%s\n", title.c_str());
    std::printf(
        "| bin | %% of volume | hex %% | prism %% | pyr %% | tet %% (of the bin's volume) | "
        "%% of all non-hex volume | cells hex/prism/pyr/tet |\n|---|---:|---:|---:|---:|---:|"
        "---:|---|\n");
    const int order[4] = {static_cast<int>(CellKind::Hex8), static_cast<int>(CellKind::Wedge6),
                          static_cast<int>(CellKind::Pyramid5), static_cast<int>(CellKind::Tet4)};
    for (std::size_t i = 0; i < bins.size(); ++i) {
      const Bin& b = bins[i];
      const double t = b.total();
      if (t <= 0) continue;
      std::printf("| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %zu/%zu/%zu/%zu |\n",
                  labels[i].c_str(), 100 * t / total_vol, 100 * b.vol[order[0]] / t,
                  100 * b.vol[order[1]] / t, 100 * b.vol[order[2]] / t, 100 * b.vol[order[3]] / t,
                  100 * (t - b.vol[order[0]]) / nonhex, b.count[order[0]], b.count[order[1]],
                  b.count[order[2]], b.count[order[3]]);
    }
  }
};

std::size_t bin_of(double x, const std::vector<double>& edges) {
  std::size_t b = 0;
  while (b < edges.size() && x >= edges[b]) ++b;
  return b;
}

std::vector<std::string> labels_of(const std::vector<double>& edges, const char* unit) {
  std::vector<std::string> l;
  char buf[64];
  for (std::size_t i = 0; i <= edges.size(); ++i) {
    if (i == 0)
      std::snprintf(buf, sizeof buf, "< %g %s", edges[0], unit);
    else if (i == edges.size())
      std::snprintf(buf, sizeof buf, ">= %g %s", edges[i - 1], unit);
    else
      std::snprintf(buf, sizeof buf, "%g-%g %s", edges[i - 1], edges[i], unit);
    l.push_back(buf);
  }
  return l;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 3) {
      std::fprintf(stderr, "usage: %s <part> <h> [options]\n", argv[0]);
      return 2;
    }
    const std::string part = argv[1];
    const double h = std::stod(argv[2]);
    VolumeOptions o;
    std::string out;
    bool quick = false;  // figures only, no tables
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> double {
        if (i + 1 >= argc) throw Error("missing value after " + a);
        return std::stod(argv[++i]);
      };
      if (a == "--k")
        o.k = next();
      else if (a == "--min-quality")
        o.min_quality = next();
      else if (a == "--max-volume-gap")
        o.max_volume_gap = next();
      else if (a == "--max-face-twist")
        o.max_face_twist = next();
      else if (a == "--min-pyramid-quality")
        o.min_pyramid_quality = next();
      else if (a == "--quick")
        quick = true;
      else if (a == "--nearest-frame")
        o.inherit_frame = false;
      else if (a == "--out" && i + 1 < argc)
        out = argv[++i];
      else
        throw Error("unknown option " + a);
    }
    const CadModel cad = CadModel::read(part);
    SurfaceOptions so;
    so.h = h;
    const SurfaceMesh surface = mesh_surface(cad, so);
    VolumeReport r;
    const MixedMesh mesh = mesh_volume(surface, o, &r);
    std::printf(
        "%s h=%g: vertices %zu (surface %zu, interior %zu); cells %zu: hex %zu prism %zu "
        "pyr %zu tet %zu; H_nbr %.2f H_vol %.2f NC %.2f Q %.3f gap %.1e\n",
        part.c_str(), h, r.stats.num_nodes, r.surface_vertices, r.interior_points,
        r.stats.num_cells, r.stats.cells_per_kind[static_cast<int>(CellKind::Hex8)],
        r.stats.cells_per_kind[static_cast<int>(CellKind::Wedge6)],
        r.stats.cells_per_kind[static_cast<int>(CellKind::Pyramid5)],
        r.stats.cells_per_kind[static_cast<int>(CellKind::Tet4)], r.stats.h_nbr, r.stats.h_vol,
        r.stats.nc_percent, r.stats.q_mean, r.volume_rel_gap);
    if (!out.empty()) write_mesh(mesh, out);
    if (quick) return 0;

    const FrameField3D field(surface);
    const SolidLocator loc(surface);
    const MixedMesh& sm = surface.mesh;
    const std::size_t nt = sm.num_bfaces();
    // Triangle normals; per CAD face the largest angle between a triangle normal and the
    // face's area-weighted mean normal (planar below 2 degrees).
    std::vector<Vec3> tn(nt);
    std::map<int, Vec3> mean_n;
    for (std::size_t t = 0; t < nt; ++t) {
      const std::int32_t* f = sm.bface(t);
      const Vec3 c =
          cross(sub(sm.nodes[f[1]], sm.nodes[f[0]]), sub(sm.nodes[f[2]], sm.nodes[f[0]]));
      tn[t] = unit(c);
      Vec3& m = mean_n[sm.bface_cad_face[t]];
      for (int a = 0; a < 3; ++a) m[a] += c[a];
    }
    std::map<int, double> max_angle;
    for (std::size_t t = 0; t < nt; ++t) {
      const Vec3 m = unit(mean_n[sm.bface_cad_face[t]]);
      const double ang = std::acos(std::min(1.0, dot(m, tn[t]))) * 180 / M_PI;
      double& a = max_angle[sm.bface_cad_face[t]];
      a = std::max(a, ang);
    }
    // CAD edges: mesh edges between triangles of different CAD faces, sampled every h/4;
    // convex when the second triangle's apex lies below the first's plane.
    std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>> edge_tris;
    for (std::size_t t = 0; t < nt; ++t) {
      const std::int32_t* f = sm.bface(t);
      for (int i = 0; i < 3; ++i) {
        const std::int32_t a = std::min(f[i], f[(i + 1) % 3]), b = std::max(f[i], f[(i + 1) % 3]);
        edge_tris[{a, b}].push_back(static_cast<std::int32_t>(t));
      }
    }
    std::vector<RValue> samples;
    std::vector<char> sample_convex;
    for (const auto& [e, ts] : edge_tris) {
      if (ts.size() != 2 || sm.bface_cad_face[ts[0]] == sm.bface_cad_face[ts[1]]) continue;
      const std::int32_t* f2 = sm.bface(ts[1]);
      std::int32_t apex = f2[0];
      for (int i = 0; i < 3; ++i)
        if (f2[i] != e.first && f2[i] != e.second) apex = f2[i];
      const double side = dot(sub(sm.nodes[apex], sm.nodes[e.first]), tn[ts[0]]);
      const bool convex = side < 0;
      const Vec3 &a = sm.nodes[e.first], &b = sm.nodes[e.second];
      const int n = std::max(1, static_cast<int>(std::ceil(norm(sub(b, a)) / (0.25 * h))));
      for (int i = 0; i <= n; ++i) {
        const double s = static_cast<double>(i) / n;
        samples.emplace_back(
            RPoint(a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])),
            static_cast<std::int32_t>(sample_convex.size()));
        sample_convex.push_back(convex);
      }
    }
    const RTree edge_tree(samples.begin(), samples.end());

    const std::vector<double> depth_edges{0.5, 1, 1.5, 2, 2.5, 3, 4, 6};
    const std::vector<double> thick_edges{1.5, 2, 2.5, 3, 3.5, 4, 5, 6, 8, 12};
    const std::vector<double> edge_edges{0.75, 1.5, 2.5};
    Table depth("Depth of the centroid below the surface (units of h)",
                labels_of(depth_edges, "h"));
    Table thick("Wall thickness through the centroid (near + far boundary along the normal)",
                labels_of(thick_edges, "h"));
    std::vector<std::string> el;
    for (const char* kind : {"convex", "concave"})
      for (const auto& l : labels_of(edge_edges, "h")) el.push_back(std::string(kind) + " " + l);
    Table edge("Distance to the nearest CAD edge (by the edge's convexity)", el);
    Table face("Nearest boundary face", {"planar", "curved (> 2 deg)"});
    Table shallow_thick("Only cells deeper than 1 h: wall thickness", labels_of(thick_edges, "h"));
    // How far the frame at the centroid (nearest surface vertex) is from the coordinate axes:
    // the largest angle between a frame vector and its nearest axis.
    const std::vector<double> dev_edges{2, 10, 25};
    Table deviation("Frame at the centroid: largest angle to the nearest coordinate axis",
                    labels_of(dev_edges, "deg"));
    Table depth_planar("Depth, nearest face planar", labels_of(depth_edges, "h"));
    Table depth_curved("Depth, nearest face curved", labels_of(depth_edges, "h"));
    double total = 0;
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      const CellKind k = mesh.cell_kind[c];
      const int nn = num_nodes(k);
      Vec3 x{0, 0, 0};
      for (int i = 0; i < nn; ++i)
        for (int a = 0; a < 3; ++a) x[a] += mesh.nodes[mesh.cell(c)[i]][a] / nn;
      const double v = cell_volume(mesh, c);
      total += v;
      const int s = mesh.cell_solid[c];
      std::int32_t tri = -1;
      const double d = loc.distance(s, x, &tri);
      const double hl = field.vertex_size(field.nearest_vertex(x));
      Vec3 u{-tn[tri][0], -tn[tri][1], -tn[tri][2]};
      const double far = loc.ray_distance(s, x, u, -1);
      const double t = std::isfinite(far) ? d + far : 1e9;
      depth.add(bin_of(d / hl, depth_edges), k, v);
      thick.add(bin_of(t / hl, thick_edges), k, v);
      if (d / hl >= 1) shallow_thick.add(bin_of(t / hl, thick_edges), k, v);
      std::vector<RValue> near;
      edge_tree.query(bgi::nearest(rp(x), 1), std::back_inserter(near));
      if (!near.empty()) {
        const double de = bg::distance(near[0].first, rp(x)) / hl;
        edge.add(
            (sample_convex[near[0].second] ? 0 : edge_edges.size() + 1) + bin_of(de, edge_edges), k,
            v);
      }
      const bool curved = max_angle[sm.bface_cad_face[tri]] > 2;
      face.add(curved ? 1 : 0, k, v);
      (curved ? depth_curved : depth_planar).add(bin_of(d / hl, depth_edges), k, v);
      {
        const Frame& F = field.vertex_frame(field.nearest_vertex(x));
        double worst = 0;
        for (const Vec3& f : F) {
          const double m = std::max({std::abs(f[0]), std::abs(f[1]), std::abs(f[2])});
          worst = std::max(worst, std::acos(std::min(1.0, m)) * 180 / M_PI);
        }
        deviation.add(bin_of(worst, dev_edges), k, v);
      }
    }
    depth.print(total);
    thick.print(total);
    shallow_thick.print(total);
    edge.print(total);
    face.print(total);
    depth_planar.print(total);
    depth_curved.print(total);
    deviation.print(total);

    // Lattice regularity of the interior vertices.
    std::vector<RValue> nodes;
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
      nodes.emplace_back(rp(mesh.nodes[i]), static_cast<std::int32_t>(i));
    const RTree node_tree(nodes.begin(), nodes.end());
    std::vector<char> in_hex(mesh.nodes.size(), 0);
    for (std::size_t c = 0; c < mesh.num_cells(); ++c)
      if (mesh.cell_kind[c] == CellKind::Hex8)
        for (int i = 0; i < 8; ++i) in_hex[mesh.cell(c)[i]] = 1;
    const std::size_t nd = depth_edges.size() + 1;
    std::vector<std::array<std::size_t, 7>> hist(nd, std::array<std::size_t, 7>{});
    std::vector<std::size_t> hexed(nd, 0), total_pts(nd, 0);
    for (std::size_t i = surface.mesh.nodes.size(); i < mesh.nodes.size(); ++i) {
      const Vec3& p = mesh.nodes[i];
      const std::int32_t nv = field.nearest_vertex(p);
      const Frame& F = field.vertex_frame(nv);
      const double hl = field.vertex_size(nv);
      int found = 0;
      for (int j = 0; j < 6; ++j) {
        const double sg = j % 2 ? -1 : 1;
        Vec3 q;
        for (int a = 0; a < 3; ++a) q[a] = p[a] + sg * hl * F[j / 2][a];
        std::vector<RValue> hit;
        node_tree.query(bgi::nearest(rp(q), 1), std::back_inserter(hit));
        if (!hit.empty() && bg::distance(hit[0].first, rp(q)) < 0.25 * hl) ++found;
      }
      const int s = loc.locate(p);
      const double d = s ? loc.distance(s, p) / hl : 0;
      const std::size_t b = bin_of(d, depth_edges);
      ++hist[b][found];
      ++total_pts[b];
      hexed[b] += in_hex[i];
    }
    const auto dl = labels_of(depth_edges, "h");
    std::printf(
        "\nInterior vertices by depth: how many of the 6 lattice neighbours x +- h d_i exist "
        "(within 0.25 h)\n| depth | vertices | 6 | 5 | 4 | 3 or fewer | in a hex %% |\n"
        "|---|---:|---:|---:|---:|---:|---:|\n");
    for (std::size_t b = 0; b < nd; ++b) {
      if (!total_pts[b]) continue;
      const double n = static_cast<double>(total_pts[b]);
      std::printf("| %s | %zu | %.1f | %.1f | %.1f | %.1f | %.1f |\n", dl[b].c_str(), total_pts[b],
                  100 * hist[b][6] / n, 100 * hist[b][5] / n, 100 * hist[b][4] / n,
                  100 * (hist[b][0] + hist[b][1] + hist[b][2] + hist[b][3]) / n,
                  100 * hexed[b] / n);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_volume_layers: error: %s\n", e.what());
    return 1;
  }
}
