// The reports of the mesher as JSON (nlohmann's to_json, one per report type) and as text.
#include "mesher/mesh_reports.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace hexfem {

namespace {

// {kind name: count} for the kinds with a count (or all of them), as a JSON object.
template <class Counts>
nlohmann::json by_kind(const Counts& n, bool skip_zero) {
  nlohmann::json j = nlohmann::json::object();
  for (int k = 0; k < kNumCellKinds; ++k)
    if (n[k] || !skip_zero) j[kind_name(static_cast<CellKind>(k))] = n[k];
  return j;
}

double vertices_per_second(const MeshReport& r) {
  return r.total_seconds > 0 ? r.volume.stats.num_nodes / r.total_seconds : 0.0;
}

// Below this the rest of the total is the time between stages, not an attempt.
constexpr double kListedRestSeconds = 0.05;

// The total less the listed stages of the mesh kept: the attempts it replaced.
double earlier_attempts_seconds(const MeshReport& r) {
  double listed = r.cad_seconds;
  for (const auto& [name, s] : r.surface.stage_seconds) listed += s;
  for (const auto& s : r.volume.stages) listed += s.seconds;
  return std::max(0.0, r.total_seconds - listed);
}

}  // namespace

void to_json(nlohmann::json& j, const VolumeReport& r) {
  j = nlohmann::json::object();
  j["vertices"] = r.stats.num_nodes;
  j["surface_vertices"] = r.surface_vertices;
  j["interior_points"] = r.interior_points;
  if (r.lp_cvt.evaluations > 0)
    j["lp_cvt"] = {{"energy_before", r.lp_cvt.energy_before},
                   {"energy_after", r.lp_cvt.energy_after},
                   {"iterations", r.lp_cvt.iterations},
                   {"evaluations", r.lp_cvt.evaluations},
                   {"moves_kept", r.lp_cvt.moves_kept}};
  j["steiner_points"] = r.steiner_points;
  if (r.frontal_points) j["frontal_points"] = r.frontal_points;
  j["tets_from_tetgen"] = r.tets;
  j["tetgen_own_seconds"] = r.tetgen_seconds;
  j["absorbed_slivers"] = r.absorbed_slivers;
  j["tets_in_elements"] = r.tets_in_elements;
  j["flat_boundary_tets"] = r.flat_boundary_tets;
  j["dissolved_pyramids"] = r.dissolved_pyramids;
  j["flat_fallback_undone"] = r.flat_fallback_undone;
  j["flat_retry_points"] = r.flat_retry_points;
  j["sliver_flips"] = r.sliver_flips;
  j["flipped_tets"] = r.flipped_tets;
  j["tets_from_flips"] = r.tets_from_flips;
  j["slivers_left"] = r.slivers_left;
  j["lifted_cells"] = r.lifted_cells;
  j["cells"] = by_kind(r.stats.cells_per_kind, false);
  j["num_cells"] = r.stats.num_cells;
  j["candidates"] = {{"hex8", r.hex_candidates},
                     {"wedge6", r.prism_candidates},
                     {"pyramid5", r.pyramid_candidates}};
  if (r.hex_swaps.rounds > 0)
    j["hex_swaps"] = {{"fillable", r.hex_swaps.fillable},
                      {"rounds", r.hex_swaps.rounds},
                      {"swaps", r.hex_swaps.swaps},
                      {"removed", r.hex_swaps.removed},
                      {"inserted", r.hex_swaps.inserted}};
  j["h_nbr_percent"] = r.stats.h_nbr;
  j["h_vol_percent"] = r.stats.h_vol;
  j["q_mean"] = r.stats.q_mean;
  j["q_min"] = r.stats.q_min;
  j["interior_quads"] = r.stats.interior_quads;
  j["nc_quads"] = r.stats.nonconformal_quads;
  j["nc_percent"] = r.stats.nc_percent;
  j["inverted"] = r.stats.inverted;
  j["boundary_triangles"] = r.boundary_triangles;
  j["boundary_quads"] = r.boundary_quads;
  j["volume_tets"] = r.volume_tets;
  j["volume_mixed"] = r.stats.volume;
  j["volume_rel_gap"] = r.volume_rel_gap;
  j["volume_elements_gap"] = r.volume_elements_gap;
  j["volume_absorbed"] = r.volume_absorbed;
  j["volume_gap_before_limit"] = r.volume_gap_before;
  j["undone_for_volume_gap"] = by_kind(r.gap_undone, true);
  j["nc_repair"] = {{"nc_faces_before", r.nc_faces_before_repair},
                    {"nc_faces_after", r.nc_faces_after_repair},
                    {"undone", by_kind(r.nc_undone, true)},
                    {"pyramids_added", r.nc_repair_pyramids},
                    {"prisms_added", r.nc_repair_prisms}};
  if (r.conformal.nc_before + r.conformal.boundary_pyramids_split +
          r.conformal.boundary_cells_split + r.conformal.bulge_quads_split >
      0) {
    const ConformalReport& c = r.conformal;
    j["conformal"] = {{"nc_faces_before", c.nc_before},
                      {"nc_faces_after", c.nc_after},
                      {"pyramids", c.pyramids},
                      {"pyramids_without_new_node", c.shell_pyramids},
                      {"pyramids_about_a_shell_node", c.flip_pyramids},
                      {"pyramids_in_a_grown_cavity", c.grown_cavities},
                      {"cells_split_with_tets_behind", c.split_with_tets_behind},
                      {"boundary_pyramids_split", c.boundary_pyramids_split},
                      {"boundary_cells_split", c.boundary_cells_split},
                      {"new_nodes", c.steiner_points},
                      {"flat_slivers_dropped", c.absorbed_slivers},
                      {"boundary_bulge",
                       {{"enclosed_gap_before", c.gap_before_bulge},
                        {"enclosed_gap_after", c.gap_after_bulge},
                        {"quads_split", c.bulge_quads_split},
                        {"quads_left", c.bulge_quads_restored}}},
                      {"cells_split", by_kind(c.cells_split, true)},
                      {"h_vol_before", c.volume > 0 ? 100 * c.hex_volume_before / c.volume : 0},
                      {"h_vol_after", c.volume > 0 ? 100 * c.hex_volume_after / c.volume : 0}};
  }
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& s : r.stages)
    stages.push_back({{"stage", s.name}, {"seconds", s.seconds}, {"cpu_seconds", s.cpu_seconds}});
  j["stages"] = stages;
  j["total_seconds"] = r.total_seconds;
  j["total_cpu_seconds"] = r.total_cpu_seconds;
  j["threads"] = r.threads;
}

std::string volume_report_text(const VolumeReport& r) {
  char buf[512];
  std::string s;
  auto line = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    s += buf;
    s += '\n';
  };
  line("vertices        %zu (surface %zu, interior %zu, steiner %zu)", r.stats.num_nodes,
       r.surface_vertices, r.interior_points, r.steiner_points);
  line("tets            %zu (%zu flat slivers on quad faces absorbed)", r.tets, r.absorbed_slivers);
  line(
      "sliver flips    %zu (%zu tets -> %zu), %zu slivers left; %zu flat tets on the surface "
      "dropped",
      r.sliver_flips, r.flipped_tets, r.tets_from_flips, r.slivers_left, r.flat_boundary_tets);
  if (r.lifted_cells)
    line("lifted          %zu slivers by moving one interior vertex each", r.lifted_cells);
  if (r.flat_fallback_undone)
    line("flat fallback   %zu elements at a flat tet's edges back to tets, flips again",
         r.flat_fallback_undone);
  if (r.flat_retry_points)
    line("flat retry      %zu interior points beside flat tets, the pipeline run again",
         r.flat_retry_points);
  line("elements        %zu: hex %zu, prism %zu, pyramid %zu, tet %zu", r.stats.num_cells,
       r.stats.cells_per_kind[static_cast<int>(CellKind::Hex8)],
       r.stats.cells_per_kind[static_cast<int>(CellKind::Wedge6)],
       r.stats.cells_per_kind[static_cast<int>(CellKind::Pyramid5)],
       r.stats.cells_per_kind[static_cast<int>(CellKind::Tet4)]);
  line("H_nbr           %.2f %%", r.stats.h_nbr);
  line("H_vol           %.2f %%", r.stats.h_vol);
  line("Q (hex)         mean %.3f, min %.3f", r.stats.q_mean, r.stats.q_min);
  line("NC              %.2f %% (%zu of %zu interior quads)", r.stats.nc_percent,
       r.stats.nonconformal_quads, r.stats.interior_quads);
  line("inverted        %zu", r.stats.inverted);
  line(
      "volume          tets %.9g, mixed %.9g, gap %.2e (elements - their tets %.4g, absorbed "
      "slivers %.4g)",
      r.volume_tets, r.stats.volume, r.volume_rel_gap, r.volume_elements_gap, r.volume_absorbed);
  line("volume gap      %.2e before undoing %zu hex, %zu prism, %zu pyramid losing most",
       std::abs(r.volume_gap_before), r.gap_undone[static_cast<int>(CellKind::Hex8)],
       r.gap_undone[static_cast<int>(CellKind::Wedge6)],
       r.gap_undone[static_cast<int>(CellKind::Pyramid5)]);
  if (r.nc_faces_before_repair > 0)  // not with --no-nc-repair
    line(
        "nc repair       %zu -> %zu NC faces: undid %zu hex, %zu prism, %zu pyramid; made %zu "
        "pyramids, %zu prisms",
        r.nc_faces_before_repair, r.nc_faces_after_repair,
        r.nc_undone[static_cast<int>(CellKind::Hex8)],
        r.nc_undone[static_cast<int>(CellKind::Wedge6)],
        r.nc_undone[static_cast<int>(CellKind::Pyramid5)], r.nc_repair_pyramids,
        r.nc_repair_prisms);
  if (r.conformal.nc_before + r.conformal.boundary_pyramids_split +
          r.conformal.boundary_cells_split + r.conformal.bulge_quads_split >
      0) {
    const ConformalReport& c = r.conformal;
    line(
        "conformal       %zu -> %zu NC faces: %zu pyramids (%zu on two tets, %zu on a filled edge "
        "shell, %zu of them about a node of the shell, %zu on a grown one), %zu cells split (hex "
        "%zu, prism %zu, pyramid %zu; %zu with the tets behind a quad), %zu new nodes; H_vol %.2f "
        "-> %.2f %%; %zu flat slivers on quads dropped; on boundary quads kept as two triangles: "
        "%zu pyramids made two tets, %zu cells split; enclosed volume %+.2e -> %+.2e of the "
        "tets' (%zu bulging boundary quads given two triangles, %zu could not be)",
        c.nc_before, c.nc_after, c.pyramids, c.shell_pyramids,
        c.pyramids - c.shell_pyramids - c.grown_cavities, c.flip_pyramids, c.grown_cavities,
        c.cells_split[0] + c.cells_split[1] + c.cells_split[2] + c.cells_split[3],
        c.cells_split[static_cast<int>(CellKind::Hex8)],
        c.cells_split[static_cast<int>(CellKind::Wedge6)],
        c.cells_split[static_cast<int>(CellKind::Pyramid5)], c.split_with_tets_behind,
        c.steiner_points, c.volume > 0 ? 100 * c.hex_volume_before / c.volume : 0,
        c.volume > 0 ? 100 * c.hex_volume_after / c.volume : 0, c.absorbed_slivers,
        c.boundary_pyramids_split, c.boundary_cells_split, c.gap_before_bulge, c.gap_after_bulge,
        c.bulge_quads_split, c.bulge_quads_restored);
  }
  for (const auto& st : r.stages)
    line("time %-22s %8.3f s wall %8.3f s cpu", st.name.c_str(), st.seconds, st.cpu_seconds);
  line("time total                 %8.3f s wall %8.3f s cpu (%d threads)", r.total_seconds,
       r.total_cpu_seconds, r.threads);
  return s;
}

void to_json(nlohmann::json& j, const MeshReport& r) {
  to_json(j, r.volume);
  j["file_unit"] = r.file_unit;
  j["length_unit"] = "mm";
  j["cad_volume"] = r.cad_volume;
  j["mesh_volume"] = r.mesh_volume;
  j["volume_error"] = r.volume_error;
  nlohmann::json solids = nlohmann::json::array();
  for (const SolidVolumeError& e : r.solids)
    solids.push_back({{"solid", e.solid},
                      {"cad_volume", e.cad_volume},
                      {"mesh_volume", e.mesh_volume},
                      {"volume_error", e.error}});
  j["solids"] = solids;
  j["warnings"] = r.warnings;
  j["refined_faces"] = r.refined_faces;
  j["surface_points"] = r.surface.points;
  j["surface_triangles"] = r.surface.triangles;
  nlohmann::json stages = nlohmann::json::array();
  stages.push_back({{"name", "cad read"}, {"seconds", r.cad_seconds}});
  for (const auto& [name, s] : r.surface.stage_seconds)
    stages.push_back({{"name", "surface: " + name}, {"seconds", s}});
  for (const auto& s : r.volume.stages)
    stages.push_back({{"name", "volume: " + s.name}, {"seconds", s.seconds}});
  // A mesh made again (finer curvature bound, refined faces) replaces the report: the attempts
  // before it still took time, which the stages must add up to.
  const double rest = earlier_attempts_seconds(r);
  if (rest >= kListedRestSeconds)
    stages.push_back({{"name", "earlier attempts (meshed again)"}, {"seconds", rest}});
  j["pipeline_stages"] = stages;
  j["total_seconds"] = r.total_seconds;
  j["vertices_per_second"] = vertices_per_second(r);
}

std::string mesh_report_text(const MeshReport& r) {
  std::string out = volume_report_text(r.volume);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "volume error     %+.3e relative to the CAD volume %.6g mm^3 (file unit %s)\n"
                "surface          %zu points, %zu triangles\n"
                "time             %.3f s total (cad read %.3f s, surface",
                r.volume_error, r.cad_volume, r.file_unit.c_str(), r.surface.points,
                r.surface.triangles, r.total_seconds, r.cad_seconds);
  out += buf;
  double surface_total = 0;
  for (const auto& [name, s] : r.surface.stage_seconds) surface_total += s;
  const double rest = earlier_attempts_seconds(r);
  char earlier[64] = "";
  if (rest >= kListedRestSeconds)
    std::snprintf(earlier, sizeof earlier, ", earlier attempts %.3f s", rest);
  std::snprintf(buf, sizeof buf, " %.3f s, volume %.3f s%s), %.0f vertices/s\n", surface_total,
                r.volume.total_seconds, earlier, vertices_per_second(r));
  out += buf;
  if (const std::string range = solid_volume_range(r.solids); !range.empty())
    out += "solids           " + range + "\n";
  return out;
}

std::string solid_volume_range(const std::vector<SolidVolumeError>& solids) {
  if (solids.size() < 2) return "";
  const auto [lo, hi] = std::minmax_element(
      solids.begin(), solids.end(), [](const auto& a, const auto& b) { return a.error < b.error; });
  char buf[200];
  std::snprintf(buf, sizeof buf, "%zu, volume error per solid %+.2e (solid %d) to %+.2e (solid %d)",
                solids.size(), lo->error, lo->solid, hi->error, hi->solid);
  return buf;
}

}  // namespace hexfem
