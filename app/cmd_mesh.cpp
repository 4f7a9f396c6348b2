// `hexfem mesh part.step --h 1.0 [--dim 3|2] -o mesh.msh|.vtu|.inp [--json] [--force]
//  [--curvature N] [--size-at vertex|edge|face:ID=S]...`: the hex-dominant mesh of a CAD part
// (--dim 3, the default; volume_mesh_cli.cpp) or its surface mesh (--dim 2).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "app/reports_json.hpp"
#include "app/volume_mesh_cli.hpp"
#include "mesher/cad/cad_model.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/pipeline.hpp"
#include "mesher/surface_check.hpp"
#include "mesher/surface_pipeline.hpp"

namespace hexfem {
namespace {

struct MeshArgs {
  std::string file;
  double h = 0;
  int dim = 3;
  int order = 1;
  std::string output;
  bool json = false;
  bool force = false;
  int curvature = 0;
  std::vector<std::string> size_at;
  VolumeOptions volume;  // --dim 3 only
  std::string hex_selection = "swap-wide";
  bool binary = false;
  double align_opposite = SurfaceOptions{}.align_opposite;
  bool edge_spacing_size = SurfaceOptions{}.sizes_from_edge_spacing;
  bool glue = false;
};

int run(const MeshArgs& a) {
  using Clock = std::chrono::steady_clock;
  if (a.dim != 2 && a.dim != 3) throw Error("--dim must be 2 (surface) or 3 (volume)");
  if (a.order != 1 && a.order != 2)
    throw Error("--order must be 1 or 2 (got " + std::to_string(a.order) + ")");
  if (a.order == 2 && a.dim != 3) throw Error("--order 2 is for volume meshes (--dim 3)");
  check_finite("--h", a.h);
  if (!(a.h > 0)) throw Error("--h must be > 0 (got " + std::to_string(a.h) + ")");
  check_input_file(a.file);
  if (!a.output.empty()) {
    check_output_file("-o", a.output, {"msh", "vtu", "inp"}, {a.file});
    check_binary_format(a.binary, a.output);
  } else if (a.binary) {
    throw Error("--binary needs an output file (-o mesh.msh)");
  }
  SurfaceOptions opt;
  opt.h = a.h;
  opt.curvature = a.curvature;
  opt.force = a.force;
  opt.align_opposite = a.align_opposite;
  opt.sizes_from_edge_spacing = a.edge_spacing_size;
  parse_size_at(a.size_at, a.h, opt.vertex_sizes, opt.face_sizes, opt.edge_sizes);
  if (a.dim == 3) {
    VolumeMeshArgs v;
    v.file = a.file;
    v.options.read.glue = a.glue;
    v.options.surface = opt;
    v.options.volume = a.volume;
    v.options.volume.hex_selection = parse_hex_selection(a.hex_selection);
    v.output = a.output;
    v.json = a.json;
    v.binary = a.binary;
    v.force = a.force;
    v.order = a.order;
    return run_volume_mesh(v);
  }

  auto t0 = Clock::now();
  const CadModel cad = CadModel::read(a.file, CadReadOptions{a.glue});
  const double read_s = std::chrono::duration<double>(Clock::now() - t0).count();
  SurfaceReport rep;
  std::vector<std::string> warnings;
  const SurfaceMesh surface = mesh_surface_closest(cad, opt, rep, warnings);
  rep.stage_seconds.insert(rep.stage_seconds.begin(), {"read CAD", read_s});

  const auto& checks = rep.checks;  // mesh_surface checked its result already
  for (const auto& c : checks) {
    if (c.ok()) continue;
    char msg[300];
    std::snprintf(msg, sizeof msg,
                  "the surface mesh of solid %d is invalid (%zu open, %zu non-manifold, %zu "
                  "misoriented edges, %s, volume %g); not written",
                  c.solid, c.open_edges, c.nonmanifold_edges, c.misoriented_edges,
                  c.self_intersects ? "self-intersecting" : "no self-intersection", c.volume);
    throw Error(msg);
  }
  double enclosed = 0;
  for (const auto& c : checks) enclosed += c.volume;
  check_mesh_volume(enclosed, cad.volume(), a.h, a.force);
  if (!a.output.empty()) {
    t0 = Clock::now();
    write_mesh(surface.mesh, a.output, MeshWriteOptions{a.binary});
    rep.stage_seconds.emplace_back("write",
                                   std::chrono::duration<double>(Clock::now() - t0).count());
  }

  double total = 0;
  for (const auto& [name, s] : rep.stage_seconds) total += s;
  if (a.json) {
    nlohmann::json j = rep;
    j["file"] = a.file;
    j["file_unit"] = cad.file_unit();
    j["h"] = a.h;
    j["cad_volume"] = cad.volume();
    for (auto& solid : j["solids"]) solid["cad_volume"] = cad.solid_volume(solid["id"].get<int>());
    if (!a.output.empty()) j["output"] = a.output;
    j["warnings"] = warnings;
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  for (const std::string& w : warnings) std::fprintf(stderr, "hexfem: warning: %s\n", w.c_str());
  std::printf("%s: %d solid(s), %d faces (file unit %s, meshed in mm)\n", a.file.c_str(),
              cad.num_solids(), cad.num_faces(), cad.file_unit().c_str());
  std::printf("h = %g: %zu points (%zu on edges; area/h^2 = %.0f), %zu triangles\n", a.h,
              rep.points, rep.edge_points, rep.estimated_points, rep.triangles);
  std::printf("right-isosceles-like triangles: %.1f %%; angles %.2f..%.2f deg, %zu below 5 deg",
              100 * rep.quality.right_isosceles_share, rep.quality.min_angle, rep.quality.max_angle,
              rep.quality.below_5);
  const auto& q = rep.quality;
  if (q.below_5 > 0 && q.below_5_at_cad_corners == q.below_5)
    std::printf(", all at CAD face corners sharper than 5 deg (%.3g..%.3g deg)",
                q.forcing_corner_min, q.forcing_corner_max);
  else if (q.below_5_at_cad_corners > 0)
    std::printf(", %zu of them at CAD face corners sharper than 5 deg (%.3g..%.3g deg)",
                q.below_5_at_cad_corners, q.forcing_corner_min, q.forcing_corner_max);
  std::printf("\n");
  if (rep.curvature_used != a.curvature)
    std::printf(
        "curvature bound %d elements per turn (the first mesh was invalid or far off the CAD "
        "volume)\n",
        rep.curvature_used);
  std::printf(
      "closed, outward, no self-intersection: %zu solid(s); enclosed volume %.9g (CAD %.9g)\n",
      checks.size(), enclosed, cad.volume());
  std::printf("time:");
  for (const auto& [name, s] : rep.stage_seconds) std::printf(" %s %.3f s,", name.c_str(), s);
  std::printf(" total %.3f s\n", total);
  if (!a.output.empty()) std::printf("wrote %s\n", a.output.c_str());
  return 0;
}

RegisterCommand reg{
    {"mesh",
     "Mesh a CAD part: hex-dominant volume mesh (--dim 3, default) or surface mesh (--dim 2)",
     [](CLI::App& sub) {
       auto a = std::make_shared<MeshArgs>();
       sub.add_option("file", a->file, "STEP, IGES or BREP file")->required();
       sub.add_option("--h", a->h, "target element size (mm)")->required();
       sub.add_option("--dim", a->dim, "2 = surface mesh, 3 = volume mesh");
       sub.add_option("--order", a->order,
                      "element order: 1 (default) or 2 (mid-edge nodes on the CAD geometry)");
       sub.add_option("-o,--output", a->output, "output mesh (.msh, .vtu, .inp)")
           ->check(kNonEmptyPath);
       sub.add_flag("--json", a->json, "print the report as JSON on stdout");
       sub.add_flag("--glue", a->glue, kGlueHelp);
       sub.add_flag(
           "--force", a->force,
           "allow more than 1 M surface points or 20 M interior points (estimated before the "
           "work), more memory than the machine has available (at least 1.35 GB per million "
           "interior points), and a mesh whose volume is more than 10 % off the CAD volume");
       sub.add_option("--curvature", a->curvature,
                      "curvature bound: N elements per 2*pi (0 = off)");
       sub.add_option(
           "--size-at", a->size_at,
           "size at a CAD vertex, edge or face, repeatable: vertex:ID=S | edge:ID=S | face:ID=S "
           "(S in mm, or 0.5h: a fraction of --h)");
       sub.add_flag("--binary", a->binary, "write MSH 4.1 binary");
       sub.add_option("--k", a->volume.k, "point exclusion factor k (paper: 0.7)");
       add_recombination_options(sub, a->volume, a->hex_selection);
       sub.add_flag("--nearest-frame{false}", a->volume.inherit_frame,
                    "interior points take the nearest surface vertex's frame (paper) instead of "
                    "their front's (study)");
       sub.add_flag("--smooth-frame", a->volume.smooth_frame,
                    "interior points take the frame of a smooth field, the surface frames "
                    "extended harmonically over a grid (study)");
       sub.add_flag("--no-coherent-first{false}", a->volume.coherent_first,
                    "every surface node's front starts at once (paper) instead of the fronts of "
                    "walls whose frames do not turn first (study)");
       sub.add_option("--coherent-axes", a->volume.coherent.min_axes,
                      "with the coherent walls first, the walls of a frame lead when they face at "
                      "least this many of its axes (default 3; study)")
           ->check(CLI::Range(1, 3));
       sub.add_option("--coherent-share", a->volume.coherent.min_share,
                      "... and hold at least this share of the surface nodes (default 0.1; study)")
           ->check(CLI::Range(0.0, 1.0));
       sub.add_option("--relax-points", a->volume.relax_points,
                      "Jacobi sweeps moving each interior point towards its lattice neighbours "
                      "after the frontal insertion (default 30; 0 = off)")
           ->check(CLI::Range(0, 1000));
       sub.add_option("--lp-cvt", a->volume.lp_cvt,
                      "L-BFGS iterations of an Lp-CVT optimisation of the interior points "
                      "after the frontal insertion (Levy and Liu 2010; study)")
           ->check(CLI::Range(0, 10000));
       sub.add_option("--lp-cvt-p", a->volume.lp_cvt_p, "the Lp-CVT exponent (even; study)")
           ->check(CLI::IsMember({2, 4, 6, 8, 10, 12, 14}));
       sub.add_option("--align-opposite", a->align_opposite,
                      "pack the two faces of a wall up to T sizes thick from the same points, "
                      "the smaller face seeded from the larger (default 2; 0 = off)")
           ->check(CLI::Range(0.0, 10.0));
       sub.add_flag("--edge-spacing-size,!--no-edge-spacing-size", a->edge_spacing_size,
                    "an edge point's size is the spacing its edge got (a whole number of "
                    "segments) where smaller and where its faces' edges agree (default; "
                    "--no-edge-spacing-size: the size field's)");
       sub.add_flag("--tetgen-delaunay-recovery", a->volume.tetgen_delaunay_recovery,
                    "let TetGen make the faces next to the boundary Delaunay again after "
                    "recovering it (tetgen -pY; slower at scale; study)");
       sub.add_flag("--random-points", a->volume.random_points,
                    "random interior points instead of frontal ones (study)");
       return [a] { return run(*a); };
     }}};

}  // namespace
}  // namespace hexfem
