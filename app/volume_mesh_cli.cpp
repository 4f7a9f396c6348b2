#include "app/volume_mesh_cli.hpp"

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/cli_checks.hpp"
#include "app/part_modal.hpp"
#include "app/reports_json.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh_reports.hpp"

namespace hexfem {

int run_volume_mesh(const VolumeMeshArgs& a) {
  MeshReport report;
  const CadModel cad = read_cad_to_mesh(a.file, a.options, report);
  MixedMesh mesh = mesh_part(cad, a.options, &report);
  Order2Report order2;
  if (a.order == 2)
    order2 =
        raise_part_to_order2(mesh, cad, !a.options.volume.no_pyramids, a.options.surface.h, report);
  check_mesh_volume(report.mesh_volume, report.cad_volume, a.options.surface.h, a.force);
  double write_seconds = 0;
  if (!a.output.empty()) {
    const auto t0 = std::chrono::steady_clock::now();
    write_mesh(mesh, a.output, mesh_write_options(mesh, a.output, a.binary, &report.warnings));
    write_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (a.json) {
    nlohmann::json j = report;
    j["file"] = a.file;
    j["h"] = a.options.surface.h;
    j["order"] = a.order;
    if (a.order == 2) j["order2"] = order2;
    if (!a.output.empty()) {
      j["output"] = a.output;
      j["write_seconds"] = write_seconds;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("%s: h = %g mm (file unit %s)\n", a.file.c_str(), a.options.surface.h,
              report.file_unit.c_str());
  std::printf("%s", mesh_report_text(report).c_str());
  if (a.order == 2) {
    std::printf(
        "order 2: %ld mid-edge nodes, %ld on the boundary, %ld curved onto the CAD geometry "
        "(largest offset %.3f edge lengths), %ld cells bent to follow it, %ld straightened; NC "
        "faces' hanging nodes: "
        "%ld placed on their quad, %ld kept; %ld NC faces made conformal (%.2f s)\n",
        order2.edge_nodes, order2.boundary_nodes, order2.curved_nodes, order2.max_offset,
        order2.bent_cells, order2.straightened_cells, order2.hanging_placed, order2.hanging_kept,
        order2.nc_made_conformal, order2.seconds());
  }
  if (!a.output.empty()) std::printf("wrote %s (%.3f s)\n", a.output.c_str(), write_seconds);
  for (const std::string& w : report.warnings)
    std::fprintf(stderr, "hexfem: warning: %s\n", w.c_str());
  return 0;
}

void add_recombination_options(CLI::App& sub, VolumeOptions& v, std::string& hex_selection) {
  sub.add_option("--min-quality", v.min_quality, "smallest scaled Jacobian of a hex or prism made");
  sub.add_option("--max-gap", v.max_total_gap,
                 "largest |V(mesh) - V(tets)| / V(tets): elements losing most go back to tets");
  sub.add_flag("--no-prisms", v.no_prisms, "make no prisms");
  sub.add_flag("--no-pyramids", v.no_pyramids, "make no pyramids");
  sub.add_flag("--no-nc-repair{false}", v.nc_repair,
               "keep elements that make more NC quad faces than they match (study)");
  sub.add_flag("--conformal", v.conformal,
               "no NC face: each made conformal with a pyramid and tets (a hex kept) or by "
               "splitting its cell");
  sub.add_option("--nc-hex-gain", v.nc_hex_gain,
                 "a hex goes back to tets when that removes at least this many NC faces");
  sub.add_option("--hex-selection", hex_selection,
                 "swap-wide (default: greedy, then swaps of hexes among the candidates around "
                 "the free tets), swap (swaps among the candidates greedy found: fewer hexes, "
                 "faster at scale) or greedy (paper: best first)")
      ->check(CLI::IsMember({"greedy", "swap", "swap-wide"}));
}

}  // namespace hexfem
