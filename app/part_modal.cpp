#include "app/part_modal.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "app/ccx_deck.hpp"
#include "app/cli_checks.hpp"
#include "fem/boundary.hpp"
#include "fem/element.hpp"
#include "fem/nc_ties.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/cad/cad_project.hpp"
#include "mesher/conformal.hpp"
#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/parallel.hpp"
#include "mesher/mesh/progress.hpp"
#include "mesher/mesh/quad8.hpp"

namespace hexfem {

bool is_cad_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == "step" || ext == "stp" || ext == "iges" || ext == "igs" || ext == "brep" ||
         ext == "rle";
}

void check_fixed_faces_exist(const CadModel& cad, const std::vector<std::string>& fix) {
  for (const std::string& spec : fix)
    for (int id : parse_fix_spec(spec).faces)
      if (id > cad.num_faces())
        throw Error("--fix '" + spec + "': face " + std::to_string(id) +
                    " does not exist (the part has faces 1.." + std::to_string(cad.num_faces()) +
                    "; see hexfem info)");
}

namespace {

// A curved cell stays curved while min/max det J over its samples (element_jacobian_ratio) is at
// least this, and a tet10 or hex20 is proven valid besides: valid, however distorted.
// Straightening a valid cell flattens its boundary faces, and one flat face on a coarse round bar
// costs more than its distortion (order2.md, "Curved cells kept curved"): a threshold of 0.05 put
// the free cylinder at h = 4 0.23 % low. The margin is for the wedges and pyramids, checked on
// samples only.
constexpr double kMinCurvedRatio = 1e-4;
// Placing a hanging node on its quad must not take a cell below this (nor below its own ratio).
constexpr double kHangingNodeMinRatio = 0.05;

// Each step timed as "order 2: <step><suffix>".
Order2Report add_order2_nodes(MixedMesh& mesh, const CadModel* cad, const std::string& suffix) {
  Order2Report report;
  StageTimer timer;
  auto lap = [&](const char* step) {
    report.stages.push_back(timer.lap(std::string("order 2: ") + step + suffix));
  };
  MidEdgeProjector project;
  // One projector per thread: each keeps its faces' and edges' OCCT projectors.
  std::vector<GeometryProjector> projectors;
  if (cad) {
    for (int t = 0; t < max_threads(); ++t) projectors.emplace_back(*cad);
    project = [&projectors](const Vec3& a, const Vec3& b, int f1, int f2) {
      const Vec3 mid{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
      return projectors[thread_index()].closest(mid, f1, f2).value_or(mid);
    };
  }
  add_mid_edge_nodes(mesh, project, &report);
  lap("mid-edge nodes");
  // Every cell's ratio, found once and kept current through the three steps.
  std::vector<double> ratios;
  bend_interior_nodes(mesh, element_jacobian_ratio, element_jacobian_ratio_at_nodes_and_points,
                      kMinCurvedRatio, &report, &ratios);
  lap("bending");
  straighten_invalid_cells(mesh, element_jacobian_ratio, kMinCurvedRatio, &report, &ratios);
  lap("straightening");
  place_hanging_nodes_on_quads(mesh, element_jacobian_ratio, kHangingNodeMinRatio, &report,
                               &ratios);
  lap("hanging nodes");
  return report;
}

// The NC quads (corner ids) of an order-2 mesh whose hanging node cannot be tied: it lies off
// the quad8 (placing it there would have degraded a cell) or its tie would be nested.
std::vector<std::array<std::int32_t, 4>> untied_nc_quads(const MixedMesh& mesh) {
  std::vector<std::array<std::int32_t, 4>> out;
  const NodeTies ties = nc_face_ties(mesh);
  if (ties.refused == 0) return out;
  for (const NcQuad8& q : nc_quad8_faces(mesh)) {
    bool untied = false;
    for (const std::int32_t h : q.diagonal) untied = untied || (h >= 0 && !ties.tied(h));
    if (untied) out.push_back({q.nodes[0], q.nodes[1], q.nodes[2], q.nodes[3]});
  }
  return out;
}

}  // namespace

Order2Report raise_to_order2(MixedMesh& mesh, const CadModel* cad, bool allow_pyramids) {
  // An untied hanging node lets its face open: the part comes out too soft, below the converged
  // frequencies (validation/order2.md section 5). With the geometry at hand those faces are
  // made conformal on the order-1 mesh (a pyramid and tets, as --conformal does everywhere) and
  // the order-2 nodes are made again.
  MixedMesh linear;
  if (cad && !mesh.nc_cell.empty()) linear = mesh;
  Order2Report report = add_order2_nodes(mesh, cad, "");
  if (!cad || linear.nodes.empty()) return report;
  StageTimer timer;
  ConformalOptions co;
  co.only_quads = untied_nc_quads(mesh);
  if (co.only_quads.empty()) return report;
  if (!allow_pyramids) {
    report.nc_left_untied = static_cast<long>(co.only_quads.size());
    return report;
  }
  const ConformalReport cr = make_conformal(linear, co);
  report.stages.push_back(timer.lap("order 2: untied NC faces made conformal"));
  Order2Report again = add_order2_nodes(linear, cad, " (again)");
  again.nc_made_conformal = static_cast<long>(cr.nc_before - cr.nc_after);
  again.stages.insert(again.stages.begin(), report.stages.begin(), report.stages.end());
  mesh = std::move(linear);
  return again;
}

Order2Report raise_part_to_order2(MixedMesh& mesh, const CadModel& cad, bool allow_pyramids,
                                  double h, MeshReport& report) {
  Order2Report o2 = raise_to_order2(mesh, &cad, allow_pyramids);
  if (o2.nc_made_conformal > 0) {
    report.stats = report.volume.stats = compute_stats(mesh);
    // The report's "vertices" are the cells' corners, as at order 1 (and in vertices/s); the
    // order-2 line adds the mid-edge nodes (the cube: 64 + 144; counted were 208 only when an
    // NC face had been made conformal).
    std::vector<char> corner(mesh.nodes.size(), 0);
    for (const std::int32_t v : mesh.cell_nodes)
      if (v >= 0) corner[v] = 1;
    report.stats.num_nodes = report.volume.stats.num_nodes =
        static_cast<std::size_t>(std::count(corner.begin(), corner.end(), 1));
  }
  // The straight cells' volume (mesh_part's) misses what the curved boundary adds back: at a
  // coarse h on a sphere -19 % straight, -0.7 % curved.
  auto& warnings = report.warnings;
  for (const std::string& straight :
       {volume_warning(report.volume_error, h), solid_volume_warning(report.solids, h)})
    if (!straight.empty())
      warnings.erase(std::remove(warnings.begin(), warnings.end(), straight), warnings.end());
  const std::vector<double> volumes = element_volumes(mesh);
  report.mesh_volume = std::accumulate(volumes.begin(), volumes.end(), 0.0);
  if (report.cad_volume > 0)
    report.volume_error = (report.mesh_volume - report.cad_volume) / report.cad_volume;
  if (const std::string w = volume_warning(report.volume_error, h); !w.empty())
    warnings.push_back(w);
  report.solids = solid_volume_errors(cad, volume_by_solid(mesh, volumes));
  if (const std::string w = solid_volume_warning(report.solids, h); !w.empty())
    warnings.push_back(w);
  if (o2.nc_left_untied > 0)
    warnings.push_back(std::to_string(o2.nc_left_untied) +
                       " NC faces have an order-2 hanging node that cannot be tied (it lies off "
                       "its quad face): free, the part is a little too soft there (without "
                       "--no-pyramids they are made conformal with a pyramid and tets)");
  return o2;
}

MeshWriteOptions mesh_write_options(const MixedMesh& mesh, const std::filesystem::path& path,
                                    bool binary, std::vector<std::string>* warnings) {
  MeshWriteOptions o;
  o.binary = binary;
  if (lower_extension(path) == "inp") {
    o.inp_reduced_pyramids = pyramids_ccx_refuses_mask(mesh);
    const std::string w = ccx_pyramid_warning(o.inp_reduced_pyramids, path);
    if (!w.empty() && warnings) warnings->push_back(w);
  }
  if (mesh.order != 2 || mesh.nc_cell.empty()) return o;
  const NodeTies ties = nc_face_ties(mesh);
  if (lower_extension(path) == "inp") {
    o.inp_ties = node_tie_list(ties);
    if (ties.refused > 0 && warnings)
      warnings->push_back(std::to_string(ties.refused) +
                          " order-2 hanging nodes of NC faces could not be tied (nested or off "
                          "their face) and are free in " +
                          path.string() + "; use --conformal");
  } else if (warnings) {
    warnings->push_back(std::to_string(ties.count + ties.refused) + " order-2 hanging nodes (" +
                        std::to_string(mesh.nc_cell.size()) + " NC quad faces) are free in " +
                        path.string() +
                        ": a solver that does not tie them sees a crack (hexfem modal ties them, "
                        "an .inp carries the ties as *EQUATION, --conformal leaves none)");
  }
  return o;
}

std::string element_formulations(int order, bool incompatible_hex) {
  if (order == 2)
    return "order 2: hex20 serendipity 3x3x3 Gauss (= CalculiX C3D20), wedge15 27 points, "
           "pyramid13 rational (Bedrosian) collapsed 27 points, tet10 27 points";
  return std::string("order 1: hex8 ") +
         (incompatible_hex ? "with incompatible modes (C3D8I-like)"
                           : "fully integrated 2x2x2 (= CalculiX C3D8)") +
         ", wedge6, pyramid5 rational, tet4";
}

PartModalResult run_part_modal(const CadModel& cad, const MeshOptions& mesh_options,
                               ModalOptions modal_options, bool force, int order) {
  using Clock = std::chrono::steady_clock;
  check_fixed_faces_exist(cad, modal_options.fix);
  PartModalResult r;
  auto t0 = Clock::now();
  r.mesh = mesh_part(cad, mesh_options, &r.mesh_report);
  if (order == 2)
    r.order2 = raise_part_to_order2(r.mesh, cad, !mesh_options.volume.no_pyramids,
                                    mesh_options.surface.h, r.mesh_report);
  r.mesh_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  r.mesh_peak_bytes = peak_rss_bytes();
  check_mesh_volume(r.mesh_report.mesh_volume, r.mesh_report.cad_volume, mesh_options.surface.h,
                    force);

  if (!modal_options.fix.empty()) {
    // The user asked for a fixed analysis: a fixed set that lets the part move is their mistake
    // (one component only, a single edge, ...), reported before the solve.
    const int unheld =
        count_unheld_rigid_motions(r.mesh, select_fixed_dofs(r.mesh, modal_options.fix));
    if (unheld > 0)
      throw Error("the fixed set leaves the part free to move (" + std::to_string(unheld) +
                  " of 6 rigid-body motions not held); fix a face or more components");
  }
  modal_options.length_scale = 1e-3;  // CAD lengths are millimetres; the solve is in SI
  show_progress("solving " + std::to_string(3 * r.mesh.nodes.size()) + " DOFs...");
  t0 = Clock::now();
  r.modal = solve_modal(r.mesh, modal_options);
  r.solve_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  end_progress();

  if (!modal_options.fix.empty() && !r.modal.eigenvalues.empty()) {
    // A clamped part has no zero-energy mode; a rigid-body mode left means the fixed set does
    // not hold it (a single node, one component only, ...).
    const double largest = r.modal.eigenvalues.back();
    if (r.modal.eigenvalues.front() < 1e-8 * largest) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "the fixed set leaves the part free to move (mode 1 at %.3g Hz is a "
                    "rigid-body mode); fix a face or more components",
                    r.modal.frequencies.front());
      throw Error(buf);
    }
  }
  return r;
}

bool incompatible_hex_from_option(const std::string& value) {
  if (value != "incompatible" && value != "full")
    throw Error("--hex8 must be incompatible or full (got '" + value + "')");
  return value == "incompatible";
}

}  // namespace hexfem
