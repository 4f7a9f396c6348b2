// Study of the surface mesher (issue 4): per model, one surface mesh and its checks.
//   bench_surface [--div D | --h H | --points N] [--curvature C] [--repeat R] [--detail]
//                 [--angles] [--corners A] FILE...
// --div D: h = bounding-box diagonal / D (default 40); --h H: that h for every file;
// --points N: h = sqrt(area / N) (a size giving about N points).
// Prints a Markdown table row per file: points, triangles, area/h^2, right-isosceles share,
// smallest angle, triangles below 5 deg (--detail: each defect on stderr, with its CAD faces),
// closed/oriented/self-intersection per solid, relative volume error against the CAD volume,
// the curvature bound used (non-zero without --curvature: the mesh failed the checks and was
// meshed again, its first attempt's time under "repair"), and the time per stage including
// the checks (best of --repeat runs). A file that cannot be meshed gets its one-line error.
// --angles: on stderr, the triangles below 5°, those forced by a CAD face corner below 5°
// grouped by corner. --corners A: the CAD face corners below A° and the mesh's angles there.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/edge_points.hpp"
#include "mesher/surface_check.hpp"
#include "mesher/surface_pipeline.hpp"

using namespace hexfem;

namespace {

struct Args {
  double div = 40, h = 0, points = 0;
  int curvature = 0, repeat = 1;
  bool detail = false;
  bool angles = false;  // list the triangles below 5°: forced ones by CAD corner, the others
  double corners = 0;   // list the CAD face corners sharper than this (degrees)
  std::vector<std::string> files;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    auto value = [&] {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", s.c_str());
        std::exit(2);
      }
      return std::atof(argv[++i]);
    };
    if (s == "--div")
      a.div = value();
    else if (s == "--h")
      a.h = value();
    else if (s == "--points")
      a.points = value();
    else if (s == "--curvature")
      a.curvature = static_cast<int>(value());
    else if (s == "--corners")
      a.corners = value();
    else if (s == "--angles")
      a.angles = true;
    else if (s == "--detail")
      a.detail = true;
    else if (s == "--repeat")
      a.repeat = std::max(1, static_cast<int>(value()));
    else
      a.files.push_back(s);
  }
  return a;
}

std::string base_name(const std::string& p) {
  const auto k = p.find_last_of('/');
  return k == std::string::npos ? p : p.substr(k + 1);
}

// On stderr, one line per CAD corner below 5° that forces triangles below 5° (how many, the
// smallest), then one line per other triangle below 5°.
void print_small_angles(const std::string& name, const CadModel& cad, const SurfaceMesh& s) {
  const MixedMesh& m = s.mesh;
  std::map<std::pair<int, int>, const CadCorner*> corner_at;  // (node, face)
  const auto corners = cad_corners(cad, m);
  for (const CadCorner& c : corners) {
    auto& slot = corner_at[{c.node, c.face}];
    if (!slot || c.angle < slot->angle) slot = &c;
  }
  std::map<const CadCorner*, std::pair<int, double>> forced;  // count, smallest
  for (std::size_t t = 0; t < m.num_bfaces(); ++t) {
    const auto* n = m.bface(t);
    const auto ang = triangle_angles(m.nodes[static_cast<std::size_t>(n[0])],
                                     m.nodes[static_cast<std::size_t>(n[1])],
                                     m.nodes[static_cast<std::size_t>(n[2])]);
    const int k = static_cast<int>(std::min_element(ang.begin(), ang.end()) - ang.begin());
    if (ang[static_cast<std::size_t>(k)] >= 5) continue;
    const auto it = corner_at.find({n[k], m.bface_cad_face[t]});
    if (it != corner_at.end() && it->second->angle < 5) {
      auto& [count, lo] = forced.try_emplace(it->second, 0, 180.0).first->second;
      ++count;
      lo = std::min(lo, ang[static_cast<std::size_t>(k)]);
      continue;
    }
    const Vec3& p = m.nodes[static_cast<std::size_t>(n[k])];
    std::fprintf(stderr, "  %s: not forced: CAD face %d, %.2f° at (%.6g, %.6g, %.6g)\n",
                 name.c_str(), m.bface_cad_face[t], ang[static_cast<std::size_t>(k)], p[0], p[1],
                 p[2]);
  }
  for (const auto& [c, f] : forced)
    std::fprintf(
        stderr,
        "  %s: forced: CAD face %d corner at vertex %d (%.3f° on the CAD): %d triangle(s), "
        "smallest %.2f°\n",
        name.c_str(), c->face, c->vertex, c->angle, f.first, f.second);
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = parse(argc, argv);
  if (a.files.empty()) {
    std::fprintf(stderr,
                 "usage: bench_surface [--div D|--h H|--points N] [--curvature C] [--repeat R] "
                 "[--detail] FILE...\n");
    return 2;
  }
  // Stage columns by name; a repaired mesh (meshed again with a curvature bound) shows the
  // curvature it used and the first attempt's time in "repair".
  const std::vector<std::string> stages{"size field",    "edge points", "cross field", "packing",
                                        "triangulation", "assembly",    "checks"};
  std::printf(
      "| model | h | points | triangles | area/h² | right-isosceles | min angle | <5° (of which at "
      "CAD "
      "face corners below 5°, the widest such corner) | closed+oriented+no self-int. | volume "
      "error | "
      "curvature | read | size | edges | cross field | packing | triangulation | assembly | "
      "checks | repair | total |\n");
  std::printf(
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& file : a.files) {
    const std::string name = base_name(file);
    try {
      auto t0 = std::chrono::steady_clock::now();
      const CadModel cad = CadModel::read(file);
      const double read_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      SurfaceOptions opt;
      const BBox3 b = cad.bbox();
      const double diag = std::hypot(b.max[0] - b.min[0], b.max[1] - b.min[1], b.max[2] - b.min[2]);
      opt.h = a.h > 0 ? a.h : a.points > 0 ? std::sqrt(cad.area() / a.points) : diag / a.div;
      opt.curvature = a.curvature;
      SurfaceReport best;
      SurfaceMesh mesh;
      double best_total = 1e300;
      for (int r = 0; r < a.repeat; ++r) {
        SurfaceReport rep;
        mesh = mesh_surface(cad, opt, &rep);
        double total = 0;
        for (const auto& [n, s] : rep.stage_seconds) total += s;
        if (total < best_total) best_total = total, best = rep;
      }
      const auto& checks = best.checks;
      std::size_t good = 0;
      double vol = 0;
      for (const auto& c : checks) {
        good += c.ok() ? 1 : 0;
        vol += c.volume;
      }
      std::printf(
          "| %s | %.4g | %zu | %zu | %.0f | %.1f %% | %.2f° | %zu (%zu, ≤ %.2f°) | %zu/%zu | %.2e "
          "| "
          "%d | %.3f",
          name.c_str(), opt.h, best.points, best.triangles, best.estimated_points,
          100 * best.quality.right_isosceles_share, best.quality.min_angle, best.quality.below_5,
          best.quality.below_5_at_cad_corners, best.quality.forcing_corner_max, good, checks.size(),
          (vol - cad.volume()) / cad.volume(), best.curvature_used, read_s);
      double repair = 0;
      for (const auto& [n, s] : best.stage_seconds)
        if (n.rfind("first attempt", 0) == 0) repair += s;
      for (const auto& stage : stages) {
        double t = 0;
        for (const auto& [n, s] : best.stage_seconds)
          if (n == stage) t += s;
        std::printf(" | %.3f", t);
      }
      std::printf(" | %.3f | %.3f |\n", repair, best_total + read_s);
      // Sharp CAD corners against the mesh: the angles at the corner's node of the face's
      // triangles (their sum is the corner as the mesh sees it).
      for (int f = 1; a.corners > 0 && f <= cad.num_faces(); ++f) {
        for (const FaceCorner& c : face_corners(cad, f)) {
          if (!(c.angle < a.corners)) continue;
          const Vec3 v = cad.vertex_point(c.vertex);
          std::size_t node = 0;
          double best_d = 1e300;
          for (std::size_t n = 0; n < mesh.mesh.nodes.size(); ++n) {
            const Vec3& x = mesh.mesh.nodes[n];
            const double d = std::hypot(x[0] - v[0], x[1] - v[1], x[2] - v[2]);
            if (d < best_d) best_d = d, node = n;
          }
          double sum = 0, lo = 180;
          int count = 0;
          for (std::size_t t = 0; t < mesh.mesh.num_bfaces(); ++t) {
            if (mesh.mesh.bface_cad_face[t] != f) continue;
            const auto* tn = mesh.mesh.bface(t);
            for (int k = 0; k < 3; ++k) {
              if (static_cast<std::size_t>(tn[k]) != node) continue;
              const auto ang =
                  triangle_angles(mesh.mesh.nodes[static_cast<std::size_t>(tn[k])],
                                  mesh.mesh.nodes[static_cast<std::size_t>(tn[(k + 1) % 3])],
                                  mesh.mesh.nodes[static_cast<std::size_t>(tn[(k + 2) % 3])]);
              sum += ang[0];
              lo = std::min(lo, ang[0]);
              ++count;
            }
          }
          std::fprintf(
              stderr,
              "  %s: face %d corner at vertex %d: CAD %.3f deg, mesh %d triangles, sum "
              "%.3f, smallest %.3f (node %.2g away), edges %d (%.3g mm) and %d (%.3g mm)\n",
              name.c_str(), f, c.vertex, c.angle, count, sum, lo, best_d,
              cad.coedges(f)[static_cast<std::size_t>(c.in_coedge)].edge,
              cad.edge_length(cad.coedges(f)[static_cast<std::size_t>(c.in_coedge)].edge),
              cad.coedges(f)[static_cast<std::size_t>(c.out_coedge)].edge,
              cad.edge_length(cad.coedges(f)[static_cast<std::size_t>(c.out_coedge)].edge));
        }
      }
      if (a.angles) print_small_angles(name, cad, mesh);
      if (a.detail)
        for (const auto& d : surface_defects(mesh))
          std::fprintf(stderr, "  %s: %s\n", name.c_str(), d.c_str());
    } catch (const std::exception& e) {
      std::printf("| %s | | error: %s | | | | | | | | | | | | | | | | | | |\n", name.c_str(),
                  e.what());
    }
    std::fflush(stdout);
  }
  return 0;
}
