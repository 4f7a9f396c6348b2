// Volume-mesher study and benchmark: runs mesh_volume on a synthetic box or cylinder surface
// (or a CAD part once the surface mesher exists) and prints the paper's table row with the time
// of every stage, and TetGen alone on the same points.
//   bench_volume box <h> | cylinder <h> | <part.step|.iges|.brep> <h> [--k K] [--min-quality Q]
//   [--no-prisms] [--no-pyramids]
//                [--random-points] [--json] [--out mesh.msh]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "mesher/cad/cad_model.hpp"
#include "mesher/frame_field_3d.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh_reports.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/surface_pipeline.hpp"
#include "mesher/tetrahedralize.hpp"
#include "mesher/volume_pipeline.hpp"
#include "mesher/volume_points.hpp"
#include "tests/support/synthetic_surfaces.hpp"

using namespace hexfem;

namespace {

SurfaceMesh make_surface(const std::string& shape, double h) {
  if (shape == "box") {
    // 2 x 1 x 1 box.
    const int n = std::max(1, static_cast<int>(std::lround(1.0 / h)));
    return synthetic::box_surface({2.0, 1.0, 1.0}, {2 * n, n, n});
  }
  if (shape == "cylinder") return synthetic::cylinder_surface(1.0, 2.0, h);
  // Anything else is a CAD file, meshed by the surface mesher.
  const CadModel cad = CadModel::read(shape);
  SurfaceOptions so;
  so.h = h;
  SurfaceReport sr;
  const auto t0 = std::chrono::steady_clock::now();
  SurfaceMesh s = mesh_surface(cad, so, &sr);
  std::fprintf(stderr, "surface: %zu points, %zu triangles in %.3f s; CAD volume %.6g\n", sr.points,
               sr.triangles,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
               cad.volume());
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc < 3) {
      std::fprintf(stderr, "usage: %s box|cylinder <h> [options]\n", argv[0]);
      return 2;
    }
    const std::string shape = argv[1];
    const double h = std::stod(argv[2]);
    VolumeOptions o;
    bool json = false;
    std::string out;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw Error("missing value after " + a);
        return argv[++i];
      };
      if (a == "--k")
        o.k = std::stod(next());
      else if (a == "--min-quality")
        o.min_quality = std::stod(next());
      else if (a == "--no-prisms")
        o.no_prisms = true;
      else if (a == "--no-pyramids")
        o.no_pyramids = true;
      else if (a == "--random-points")
        o.random_points = true;
      else if (a == "--jitter")
        o.jitter = std::stod(next());
      else if (a == "--max-volume-gap")
        o.max_volume_gap = std::stod(next());
      else if (a == "--max-face-twist")
        o.max_face_twist = std::stod(next());
      else if (a == "--json")
        json = true;
      else if (a == "--out")
        out = next();
      else
        throw Error("unknown option " + a);
    }
    const SurfaceMesh surface = make_surface(shape, h);
    VolumeReport r;
    const MixedMesh mesh = mesh_volume(surface, o, &r);
    // TetGen alone on the same points (frontal insertion redone outside the timing).
    const FrameField3D field(surface);
    const SolidLocator loc(surface);
    VolumePointsOptions po;
    po.k = o.k;
    po.random = o.random_points;
    po.jitter = o.jitter;
    const VolumePoints vp = insert_volume_points(surface, field, loc, po);
    const auto t0 = std::chrono::steady_clock::now();
    const TetMesh tm = tetrahedralize(surface, vp.points, loc);
    const double tetgen_alone =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (json) {
      nlohmann::json j = r;
      j["shape"] = shape;
      j["h"] = h;
      j["tetgen_alone_seconds"] = tetgen_alone;
      j["vertices_per_second"] = r.stats.num_nodes / r.total_seconds;
      std::cout << j.dump(2) << "\n";
    } else {
      std::printf("%s h=%g\n%s", shape.c_str(), h, volume_report_text(r).c_str());
      std::printf("tetgen alone               %.3f s (%zu tets)\n", tetgen_alone, tm.tets.size());
      std::printf("speed                      %.0f vertices/s\n",
                  r.stats.num_nodes / r.total_seconds);
    }
    if (!out.empty()) write_mesh(mesh, out);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_volume: error: %s\n", e.what());
    return 1;
  }
}
