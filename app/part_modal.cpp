#include "app/part_modal.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "app/cli_checks.hpp"
#include "fem/boundary.hpp"
#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/progress.hpp"

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

PartModalResult run_part_modal(const CadModel& cad, const MeshOptions& mesh_options,
                               ModalOptions modal_options, bool force) {
  using Clock = std::chrono::steady_clock;
  check_fixed_faces_exist(cad, modal_options.fix);
  PartModalResult r;
  auto t0 = Clock::now();
  r.mesh = mesh_part(cad, mesh_options, &r.mesh_report);
  r.mesh_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
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
