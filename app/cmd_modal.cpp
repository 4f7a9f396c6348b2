// `hexfem modal mesh.msh|part.step [--h 1.0] --fix SPEC... [--material steel | --E --nu --rho]
//  [--modes 10] [--units SI|mm] [--hex8 incompatible|full] [--json] [--modes-out modes.vtu]`:
// natural frequencies of a meshed solid, or of a CAD part meshed hex-dominant in the same run.
// The reusable parts live in fem/ (solve_modal, select_fixed_nodes); this file only reads the
// mesh, states units and material, and prints.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/ccx_deck.hpp"
#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "app/modal_cli.hpp"
#include "app/part_modal.hpp"
#include "app/reports_json.hpp"
#include "fem/boundary.hpp"
#include "fem/material.hpp"
#include "fem/modal_solver.hpp"
#include "fem/mode_shapes_vtu.hpp"
#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh_reports.hpp"

namespace hexfem {
namespace {

// ", curvature bound N per turn" when the mesh had one (the order-2 default or --curvature).
std::string curvature_note(int curvature) {
  return curvature > 0 ? ", curvature bound " + std::to_string(curvature) + " per turn" : "";
}

struct Args {
  std::string mesh;
  ModalCliOptions modal;  // --fix --material --E --nu --rho --modes --hex8 --force
  bool free = false;
  std::string units = "SI";
  CLI::Option* units_given = nullptr;  // a CAD part's lengths are mm: --units is for meshes
  bool json = false;
  std::string modes_out;
  std::string ccx_deck;  // --ccx-deck JOB.inp (and JOB_mesh.inp)
  // CAD input only: mesh size (mm) and where to write the mesh.
  double h = 0;
  std::string mesh_out;
};

struct Units {
  std::string name;  // "SI" or "mm"
  double scale;      // mesh coordinate * scale = metres
};

Units parse_units(const std::string& u) {
  if (u == "SI" || u == "si" || u == "m") return {"SI", 1.0};
  if (u == "mm") return {"mm", 1e-3};
  throw Error("--units must be SI (metres) or mm, got '" + u + "'");
}

// A mesh file's unit: the one it records (hexfem's meshes record mm), else --units, else metres.
// A --units that contradicts the record is refused: one of the two is wrong, and the
// frequencies would be off by a factor of a thousand.
Units mesh_units(const Args& a, const MixedMesh& mesh) {
  if (mesh.length_unit.empty()) return parse_units(a.units);
  const Units recorded = parse_units(mesh.length_unit);
  if (given(a.units_given) && parse_units(a.units).name != recorded.name)
    throw Error("'" + a.mesh + "' records its coordinates in " + mesh.length_unit + "; --units " +
                a.units + " contradicts it (leave --units out)");
  return recorded;
}

// Plausibility of the length unit: a part of tens of metres in "SI" is most likely in mm.
std::vector<std::string> unit_warnings(const MixedMesh& mesh, const Units& units) {
  double extent = 0;
  for (int a = 0; a < 3; ++a) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : mesh.nodes) {
      lo = std::min(lo, p[a]);
      hi = std::max(hi, p[a]);
    }
    if (hi > lo) extent = std::max(extent, hi - lo);
  }
  const double metres = extent * units.scale;
  std::vector<std::string> w;
  char buf[240];
  if (units.name == "SI" && metres > 10) {
    std::snprintf(buf, sizeof buf,
                  "the mesh spans %.4g m with --units SI; if its coordinates are millimetres, "
                  "use --units mm",
                  metres);
    w.push_back(buf);
  } else if (units.name == "mm" && metres < 1e-4) {
    std::snprintf(buf, sizeof buf,
                  "the mesh spans %.4g mm with --units mm; if its coordinates are metres, use "
                  "--units SI",
                  extent);
    w.push_back(buf);
  }
  return w;
}

// Every check that needs no mesh, before any work: options, then input and output paths.
ModalOptions check_arguments(const Args& a, bool cad_input) {
  parse_units(a.units);
  const auto& fix = a.modal.fix;
  if (fix.empty() && !a.free)
    throw Error(
        "no boundary condition: give --fix (e.g. --fix face:1 or --fix \"x<0.001\") or "
        "--free for a free-free analysis");
  if (!fix.empty() && a.free) throw Error("--free and --fix exclude each other");
  ModalOptions opt = modal_options_from(a.modal);
  check_input_file(a.mesh);
  const bool order_given = given(a.modal.order_given);
  check_hex8_for_order(a.modal, a.modal.order == 2 && (cad_input || order_given));
  if (cad_input) {
    check_finite("--h", a.h);
    if (!(a.h > 0)) throw Error("a CAD input needs a mesh size: --h > 0 (mm)");
    if (given(a.units_given) && parse_units(a.units).name != "mm")
      throw Error("--units " + a.units +
                  " does not apply to a CAD part: it is meshed in millimetres (its file unit "
                  "converted) and solved in SI; --units is for a mesh input");
  } else {
    if (a.modal.force) throw Error("--force is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.h != 0) throw Error("--h is for CAD input; '" + a.mesh + "' is already a mesh");
    if (!a.mesh_out.empty())
      throw Error("--mesh-out is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.conformal)
      throw Error("--conformal is for CAD input; '" + a.mesh + "' is already a mesh");
    if (!a.modal.size_at.empty())
      throw Error("--size-at is for CAD input; '" + a.mesh + "' is already a mesh");
    if (given(a.modal.curvature_given))
      throw Error("--curvature is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.relax_points != -1)
      throw Error("--relax-points is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.coherent_first)
      throw Error("--coherent-first is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.align_opposite != -1)
      throw Error("--align-opposite is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.no_edge_spacing_size)
      throw Error("--no-edge-spacing-size is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.no_pyramids)
      throw Error("--no-pyramids is for CAD input; '" + a.mesh + "' is already a mesh");
    if (a.modal.glue) throw Error("--glue is for CAD input; '" + a.mesh + "' is already a mesh");
    if (given(a.modal.singular_size_given))
      throw Error("--singular-size is for CAD input; '" + a.mesh + "' is already a mesh");
  }
  if (!a.mesh_out.empty())
    check_output_file("--mesh-out", a.mesh_out, {"msh", "vtu", "inp"}, {a.mesh});
  if (!a.ccx_deck.empty()) {
    std::vector<std::string> inputs{a.mesh};
    if (!a.mesh_out.empty()) inputs.push_back(a.mesh_out);
    check_output_file("--ccx-deck", a.ccx_deck, {"inp"}, inputs);
    check_output_file("--ccx-deck", ccx_deck_mesh_path(a.ccx_deck).string(), {"inp"}, inputs);
  }
  if (!a.modes_out.empty()) {
    check_output_file("--modes-out", a.modes_out, {"vtu"}, {a.mesh});
    if (!a.mesh_out.empty() && lower_extension(a.mesh_out) == "vtu")
      check_output_file("--modes-out", a.modes_out, {"vtu"}, {a.mesh_out});
  }
  return opt;
}

int run(const Args& a) {
  Units units = parse_units(a.units);
  const bool cad_input = is_cad_file(a.mesh);
  ModalOptions opt = check_arguments(a, cad_input);
  opt.length_scale = units.scale;
  const SolidMaterials& mat = opt.material;

  // A CAD part is meshed first (lengths in mm) and solved in the same process.
  MixedMesh mesh;
  bool read_order2 = false;  // a second-order mesh file: its own mid-edge nodes, none made
  ModalResult r;
  PartModalResult part;
  GradedEdges graded;  // --singular-size, for the report
  if (cad_input) {
    const CadModel cad = CadModel::read(a.mesh, CadReadOptions{a.modal.glue});
    check_material_solids(opt.material, cad);
    graded = singular_edges_graded(a.modal, cad);
    const MeshOptions mesh_options = cad_mesh_options(a.modal, a.h, graded);
    part = run_part_modal(cad, mesh_options, opt, a.modal.force, a.modal.order);
    mesh = std::move(part.mesh);
    r = std::move(part.modal);
    if (!a.mesh_out.empty())
      write_mesh(mesh, a.mesh_out,
                 mesh_write_options(mesh, a.mesh_out, false, &part.mesh_report.warnings));
  } else {
    mesh = read_mesh(a.mesh);
    units = mesh_units(a, mesh);
    opt.length_scale = units.scale;
    read_order2 = mesh.order == 2;
    const bool order_given = given(a.modal.order_given);
    if (order_given && a.modal.order == 2 && mesh.order == 1)
      part.order2 = raise_to_order2(mesh, nullptr);  // no geometry: straight edges
    if (order_given && a.modal.order == 1 && mesh.order == 2) {
      // Order 1 on a second-order mesh: its corners only; the mid-edge nodes are left unused
      // (no DOF is numbered for a node no cell holds).
      mesh.order = 1;
      mesh.cell_edge_nodes.clear();
      mesh.bface_edge_nodes.clear();
      read_order2 = false;
    }
    r = solve_modal(mesh, opt);
  }
  const Units shown = cad_input ? Units{"mm", 1e-3} : units;
  // Where the length unit came from, for the report.
  const char* unit_source = cad_input                   ? "the CAD file, converted to mm"
                            : !mesh.length_unit.empty() ? "recorded in the mesh file"
                            : given(a.units_given)      ? "--units"
                                                        : "default (the file records none)";
  std::vector<std::string> warnings =
      cad_input ? part.mesh_report.warnings : unit_warnings(mesh, units);
  std::int32_t parts = 1;
  if (a.free) {
    connected_parts(mesh, NodeTies{}, &parts);
    if (parts > 1)
      warnings.push_back("the mesh has " + std::to_string(parts) +
                         " unconnected parts: the first " + std::to_string(6 * parts) +
                         " modes are rigid-body modes (six per part)");
  }
  std::vector<std::size_t> fixed_nodes;
  for (const std::string& spec : a.modal.fix)
    fixed_nodes.push_back(select_fixed_nodes(mesh, spec).nodes.size());

  // Rigid-body modes left although DOFs are fixed: legitimate for partial supports (NAFEMS
  // FV52), a mistake otherwise; say so either way.
  int rigid = 0;
  const double lam_max = r.eigenvalues.back();
  for (double lam : r.eigenvalues) rigid += std::abs(lam) < 1e-8 * std::abs(lam_max);
  if (!a.modal.fix.empty() && rigid > 0)
    warnings.push_back(std::to_string(rigid) +
                       " rigid-body mode(s) left: the fixed DOFs do not hold the part in every "
                       "direction");
  if (!a.modes_out.empty()) write_mode_shapes_vtu(mesh, r, a.modes_out);
  CcxDeckFiles deck;
  if (!a.ccx_deck.empty()) {
    ModalOptions as_solved = opt;
    as_solved.length_scale = shown.scale;  // a CAD part is meshed in mm
    deck = write_ccx_deck(mesh, as_solved, select_fixed_dofs(mesh, a.modal.fix), a.ccx_deck);
    if (!deck.warning.empty()) warnings.push_back(deck.warning);
  }

  std::size_t count[kNumCellKinds] = {};
  for (CellKind k : mesh.cell_kind) ++count[static_cast<int>(k)];
  if (a.json) {
    nlohmann::json j = r;  // DOFs, mass, volume, modes, solver figures
    j["mesh"] = {{"file", a.mesh},
                 {"nodes", mesh.nodes.size()},
                 {"cells", mesh.num_cells()},
                 {"nc_quad_faces", mesh.nc_cell.size()}};
    for (int k = 0; k < kNumCellKinds; ++k) j["mesh"][kind_name(CellKind(k))] = count[k];
    if (cad_input) {
      j["mesh"]["h"] = a.h;
      j["mesh"]["curvature_bound"] = part.mesh_report.surface.curvature_used;
      if (graded.fraction > 0)
        j["mesh"]["singular_edges"] = {{"fraction_of_h", graded.fraction},
                                       {"reentrant", graded.reentrant},
                                       {"clamp_rim", graded.rim},
                                       {"by_default", graded.by_default}};
      j["mesh"]["report"] = part.mesh_report;  // the mesher's report, as `hexfem mesh --json`
      j["mesh"]["mesh_seconds"] = part.mesh_seconds;
      j["mesh"]["peak_memory_bytes"] = part.mesh_peak_bytes;
      if (!a.mesh_out.empty()) j["mesh"]["written"] = a.mesh_out;
    }
    if (mesh.order == 1) j["hex8"] = a.modal.hex8;  // order 2 has no hex8: "elements" says what
    j["order"] = mesh.order;
    j["elements"] = element_formulations(mesh.order, opt.incompatible_hex);
    if (read_order2)
      j["order2"] = {{"mid_edge_nodes", "as read"}};
    else if (mesh.order == 2)
      j["order2"] = part.order2;
    j["units"] = {{"length", shown.name == "SI" ? "m" : "mm"},
                  {"scale_to_m", shown.scale},
                  {"length_from", unit_source},
                  {"material", "SI (Pa, kg/m^3)"},
                  {"frequency", "Hz"}};
    j["material"] = mat;
    j["fix"] = a.modal.fix;
    j["warnings"] = warnings;
    if (!a.modes_out.empty()) j["modes_out"] = a.modes_out;
    if (!deck.deck.empty()) j["ccx_deck"] = {deck.deck.string(), deck.mesh.string()};
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }

  for (const std::string& w : warnings) std::fprintf(stderr, "hexfem: warning: %s\n", w.c_str());
  std::printf("mesh      %s: %zu nodes, %zu cells (", a.mesh.c_str(), mesh.nodes.size(),
              mesh.num_cells());
  bool first = true;
  for (int k = kNumCellKinds - 1; k >= 0; --k)
    if (count[k]) {
      std::printf("%s%s %zu", first ? "" : ", ", kind_name(CellKind(k), mesh.order), count[k]);
      first = false;
    }
  std::printf("), %zu non-conformal quad faces\n", mesh.nc_cell.size());
  if (cad_input)
    std::printf(
        "hexmesh   h = %g mm%s: H_nbr %.2f %%, H_vol %.2f %%, Q %.3f, NC %.2f %%, inverted %zu, "
        "volume error %+.2e (%.2f s, peak memory %.2f GB)%s%s\n",
        a.h, curvature_note(part.mesh_report.surface.curvature_used).c_str(),
        part.mesh_report.stats.h_nbr, part.mesh_report.stats.h_vol, part.mesh_report.stats.q_mean,
        part.mesh_report.stats.nc_percent, part.mesh_report.stats.inverted,
        part.mesh_report.volume_error, part.mesh_seconds, part.mesh_peak_bytes / 1e9,
        a.mesh_out.empty() ? "" : "; written to ", a.mesh_out.c_str());
  if (const std::string range = solid_volume_range(part.mesh_report.solids);
      cad_input && !range.empty())
    std::printf("solids    %s\n", range.c_str());
  if (graded.fraction > 0) std::printf("grading   %s\n", graded.note().c_str());
  std::printf("elements  %s\n", element_formulations(mesh.order, opt.incompatible_hex).c_str());
  if (read_order2)
    std::printf("order 2   the mid-edge nodes as read from %s\n", a.mesh.c_str());
  else if (mesh.order == 2)
    std::printf(
        "order 2   %ld mid-edge nodes, %ld on the boundary, %ld curved onto the CAD geometry "
        "(largest offset %.3f edge lengths, %ld projections refused), %ld cells bent to follow "
        "it, %ld straightened; "
        "NC faces' hanging nodes: %ld placed on their quad, %ld kept; %ld NC faces made "
        "conformal\n",
        part.order2.edge_nodes, part.order2.boundary_nodes, part.order2.curved_nodes,
        part.order2.max_offset, part.order2.projection_refused, part.order2.bent_cells,
        part.order2.straightened_cells, part.order2.hanging_placed, part.order2.hanging_kept,
        part.order2.nc_made_conformal);
  std::printf("units     lengths in %s (%s; x %g -> m), material in SI, frequencies in Hz\n",
              shown.name == "SI" ? "m" : "mm", unit_source, shown.scale);
  std::printf("material  %s: E = %.6g Pa, nu = %g, rho = %g kg/m^3\n", mat.base.name.c_str(),
              mat.base.E, mat.base.nu, mat.base.rho);
  for (const auto& [solid, m] : mat.by_solid)
    std::printf("material  solid %d: %s: E = %.6g Pa, nu = %g, rho = %g kg/m^3\n", solid,
                m.name.c_str(), m.E, m.nu, m.rho);
  if (a.modal.fix.empty())
    std::printf(
        "boundary  free-free (%d rigid-body modes expected near 0 Hz: six per "
        "connected part)\n",
        6 * parts);
  for (std::size_t i = 0; i < a.modal.fix.size(); ++i)
    std::printf("boundary  --fix %s: %zu nodes\n", a.modal.fix[i].c_str(), fixed_nodes[i]);
  std::printf(
      "model     %ld free DOFs, %ld fixed, %ld nonzeros in K; mass %.6g kg, volume %.6g m^3\n",
      r.num_free_dofs, r.num_fixed_dofs, r.stiffness_nnz, r.total_mass, r.volume);
  if (r.eigen.method == "iterative")
    std::printf(
        "solver    iterative (%s + PETSc GAMG, %d rank%s; %s): assembly %.2f s, AMG "
        "setup %.2f s, eigensolver %.2f s (%ld iterations), max residual %.1e, peak memory "
        "%.2f GB (%.2f GB by the end of assembly, %.2f GB of AMG setup)\n\n",
        r.eigen.algorithm.c_str(), r.eigen.ranks, r.eigen.ranks > 1 ? "s" : "",
        r.solver_reason.c_str(), r.assemble_seconds, r.eigen.setup_seconds, r.eigen.solve_seconds,
        r.eigen.iterations, r.eigen.max_residual, r.eigen.peak_memory_bytes / 1e9,
        r.eigen.peak_memory_assembly_bytes / 1e9, r.eigen.peak_memory_setup_bytes / 1e9);
  else
    std::printf(
        "solver    direct (CHOLMOD + Spectra; %s): order %.2f s, assembly %.2f s, factorization "
        "%.2f s (factor %.2f GB), Lanczos %.2f s, max residual %.1e, peak memory %.2f GB\n\n",
        r.solver_reason.c_str(), r.order_seconds, r.assemble_seconds, r.eigen.factor_seconds,
        r.eigen.factor_bytes / 1e9, r.eigen.solve_seconds, r.eigen.max_residual,
        r.eigen.peak_memory_bytes / 1e9);
  std::printf("mode  frequency [Hz]   effective mass [%% of total]\n");
  std::printf("                          x         y         z\n");
  double sum[3] = {0, 0, 0};
  for (std::size_t m = 0; m < r.frequencies.size(); ++m) {
    std::printf("%4zu  %14.6g  %8.3f  %8.3f  %8.3f\n", m + 1, r.frequencies[m],
                100 * r.effective_mass_fraction(m, 0), 100 * r.effective_mass_fraction(m, 1),
                100 * r.effective_mass_fraction(m, 2));
    for (int d = 0; d < 3; ++d) sum[d] += r.effective_mass_fraction(m, d);
  }
  std::printf(" sum  %14s  %8.3f  %8.3f  %8.3f   (free DOFs carry %.3f / %.3f / %.3f)\n", "",
              100 * sum[0], 100 * sum[1], 100 * sum[2], 100 * r.free_mass[0] / r.total_mass,
              100 * r.free_mass[1] / r.total_mass, 100 * r.free_mass[2] / r.total_mass);
  if (!a.modes_out.empty()) std::printf("\nmode shapes written to %s\n", a.modes_out.c_str());
  if (!deck.deck.empty())
    std::printf("CalculiX deck written to %s (mesh in %s): run `ccx %s` in its folder\n",
                deck.deck.c_str(), deck.mesh.filename().c_str(), deck.deck.stem().c_str());
  return 0;
}

RegisterCommand reg{
    {"modal", "Natural frequencies of a CAD part (meshed hex-dominant first) or of a mesh",
     [](CLI::App& sub) {
       auto a = std::make_shared<Args>();
       sub.add_option("mesh", a->mesh,
                      "volume mesh (.msh), or a CAD part (.step .iges .brep, lengths in mm) that "
                      "is meshed first with --h")
           ->required();
       sub.add_option("--h", a->h, "CAD input: target element size in mm");
       sub.add_option("--mesh-out", a->mesh_out, "CAD input: also write the mesh (.msh .vtu .inp)")
           ->check(kNonEmptyPath);
       add_modal_options(sub, a->modal);
       sub.add_flag("--free", a->free, "free-free analysis (no fixed DOF)");
       a->units_given = sub.add_option("--units", a->units,
                                       "mesh input: length unit of the mesh, SI (m) or mm; "
                                       "default: the unit the file records (hexfem's .msh "
                                       "files record mm), else SI");
       sub.add_flag("--json", a->json, "print JSON on stdout");
       sub.add_option("--modes-out", a->modes_out, "write mode shapes to this .vtu (ParaView)")
           ->check(kNonEmptyPath);
       sub.add_option("--ccx-deck", a->ccx_deck,
                      "also write this analysis as a CalculiX deck JOB.inp (+ JOB_mesh.inp): "
                      "materials, fixed DOFs, *FREQUENCY; `ccx JOB` checks the frequencies")
           ->check(kNonEmptyPath);
       return [a] { return run(*a); };
     }}};

}  // namespace
}  // namespace hexfem
