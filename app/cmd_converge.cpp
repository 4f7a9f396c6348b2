// hexfem converge part.step --h 2,1,0.5 --fix face:8 [--reference ref.json]: the paper's Table 2.
// Meshes and solves the part at each size, then prints and writes the table (CSV, Markdown) with
// errors against the reference, the observed order, and a log-log plot of error versus h.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/cli_checks.hpp"
#include "app/command_registry.hpp"
#include "app/convergence_table.hpp"
#include "app/modal_cli.hpp"
#include "app/part_modal.hpp"
#include "app/reports_json.hpp"
#include "fem/material.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

struct ConvergeArgs {
  std::string file;
  std::vector<double> sizes;
  ModalCliOptions modal;  // --fix --material --E --nu --rho --modes --hex8 --force
  std::string reference;
  std::string output;
  bool json = false;
  ConvergeArgs() { modal.modes = 6; }
};

int run(const ConvergeArgs& a) {
  if (!is_cad_file(a.file)) throw Error("'" + a.file + "' is not a CAD file (.step .iges .brep)");
  if (a.sizes.empty()) throw Error("--h needs at least one size");
  for (double h : a.sizes)
    if (!(h > 0) || !std::isfinite(h)) throw Error("--h: every size must be finite and > 0");
  // The observed order and the monotone test read the rows from coarse to fine.
  for (std::size_t i = 1; i < a.sizes.size(); ++i)
    if (!(a.sizes[i] < a.sizes[i - 1])) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "--h: the sizes must go from coarse to fine, each smaller than the last (%g "
                    "then %g)",
                    a.sizes[i - 1], a.sizes[i]);
      throw Error(buf);
    }
  if (a.modal.fix.empty())
    throw Error("--fix is required for a convergence study (e.g. --fix face:8)");
  const ModalOptions modal = modal_options_from(a.modal);
  check_hex8_for_order(a.modal, a.modal.order == 2);
  check_input_file(a.file);
  if (!a.output.empty()) check_output_folder("-o", a.output);

  ConvergenceStudy study;
  study.part = std::filesystem::path(a.file).filename().string();
  if (!a.reference.empty()) {
    study.reference = read_reference_json(a.reference);
    study.reference_source = a.reference;
  }
  const CadModel cad = CadModel::read(a.file, CadReadOptions{a.modal.glue});
  check_material_solids(modal.material, cad);
  check_fixed_faces_exist(cad, a.modal.fix);

  std::vector<std::pair<std::string, std::string>> solvers;  // per row: path taken, why
  std::vector<int> curvature;  // per row: the mesh's curvature bound (0 = none)
  const GradedEdges graded = singular_edges_graded(a.modal, cad);
  for (std::size_t i = 0; i < a.sizes.size(); ++i) {
    const MeshOptions mesh = cad_mesh_options(a.modal, a.sizes[i], graded);
    std::fprintf(stderr, "converge: run %zu/%zu, h = %g ...\n", i + 1, a.sizes.size(), a.sizes[i]);
    const PartModalResult r = run_part_modal(cad, mesh, modal, a.modal.force, a.modal.order);
    ConvergenceRow row;
    row.h = a.sizes[i];
    row.nodes = static_cast<long>(r.mesh.nodes.size());
    row.cells = static_cast<long>(r.mesh.num_cells());
    row.h_vol = r.mesh_report.stats.h_vol;
    row.h_nbr = r.mesh_report.stats.h_nbr;
    row.seconds = r.mesh_seconds + r.solve_seconds;
    row.frequencies = r.modal.frequencies;
    solvers.emplace_back(r.modal.eigen.method, r.modal.solver_reason);
    curvature.push_back(r.mesh_report.surface.curvature_used);
    std::fprintf(stderr,
                 "converge: h = %g: %ld cells, H_vol %.2f %%, curvature bound %d per turn, f1 %.3f "
                 "Hz (%.1f s, %s)\n",
                 row.h, row.cells, row.h_vol, curvature.back(),
                 row.frequencies.empty() ? 0.0 : row.frequencies[0], row.seconds,
                 r.modal.solver_reason.c_str());
    study.rows.push_back(std::move(row));
  }

  const std::string stem =
      a.output.empty() ? std::filesystem::path(a.file).stem().string() + "_converge" : a.output;
  const auto files = write_convergence_files(study, stem);
  if (a.json) {
    nlohmann::json j = study;
    j["part"] = a.file;
    j["material"] = modal.material;
    if (a.modal.order == 1) j["hex8"] = a.modal.hex8;  // order 2: "elements" says what
    j["order"] = a.modal.order;
    j["elements"] = element_formulations(a.modal.order, modal.incompatible_hex);
    j["fix"] = a.modal.fix;
    for (std::size_t r = 0; r < study.rows.size(); ++r) {
      j["rows"][r]["solver"] = solvers[r].first;
      j["rows"][r]["solver_reason"] = solvers[r].second;
      j["rows"][r]["curvature_bound"] = curvature[r];
    }
    for (const auto& f : files) j["files"].push_back(f.string());
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::string fixed;
  for (const std::string& f : a.modal.fix) fixed += (fixed.empty() ? "" : ", ") + f;
  std::printf("%s: material %s, fixed %s; lengths in mm, frequencies in Hz\nelements %s\n",
              study.part.c_str(), material_summary(modal.material).c_str(), fixed.c_str(),
              element_formulations(a.modal.order, modal.incompatible_hex).c_str());
  // One bound for every row, or the rows' own (the mesher's retries may raise it for one h).
  const bool same_bound = std::all_of(curvature.begin(), curvature.end(),
                                      [&](int c) { return c == curvature.front(); });
  // Not given: order 2 has a default bound; at order 1 any bound is the mesher's volume retry.
  const char* origin = given(a.modal.curvature_given) ? ""
                       : a.modal.order == 2
                           ? " (the order-2 default, never finer than h/2; --curvature 0 turns it "
                             "off)"
                           : " (none asked: the mesher's, where the mesh was off the CAD volume)";
  if (graded.fraction > 0) std::printf("meshes   %s\n", graded.note().c_str());
  if (!curvature.empty() && same_bound && curvature.front() > 0)
    std::printf("meshes   curvature bound %d elements per turn on curved edges and faces%s\n",
                curvature.front(), origin);
  else if (!same_bound) {
    std::string bounds;
    for (int c : curvature) bounds += (bounds.empty() ? "" : ", ") + std::to_string(c);
    std::printf(
        "meshes   curvature bound per h, elements per turn on curved edges and faces (0 = "
        "none): %s%s\n",
        bounds.c_str(), origin);
  }
  std::printf("%s", convergence_text(study).c_str());
  for (const auto& f : files) std::printf("wrote %s\n", f.string().c_str());
  return 0;
}

RegisterCommand reg{
    {"converge", "Frequencies of a CAD part over mesh sizes (the paper's Table 2)",
     [](CLI::App& sub) -> std::function<int()> {
       auto a = std::make_shared<ConvergeArgs>();
       sub.add_option("file", a->file, "STEP, IGES or BREP file (lengths in mm)")->required();
       sub.add_option("--h", a->sizes, "mesh sizes, coarse to fine, e.g. 2,1,0.5")
           ->required()
           ->delimiter(',');
       add_modal_options(sub, a->modal);
       sub.add_option("--reference", a->reference, "JSON with \"reference_hz\": [...]");
       sub.add_option("-o,--output", a->output, "stem of the CSV/Markdown/PNG files")
           ->check(kNonEmptyPath);
       sub.add_flag("--json", a->json, "print the study as JSON");
       return [a] { return run(*a); };
     }}};

}  // namespace
}  // namespace hexfem
