#include "app/reports_json.hpp"

#include <cmath>

namespace hexfem {

void to_json(nlohmann::json& j, const Material& m) {
  j = {{"name", m.name}, {"E", m.E}, {"nu", m.nu}, {"rho", m.rho}};
}

void to_json(nlohmann::json& j, const SolidMaterials& m) {
  j = m.base;
  if (m.by_solid.empty()) return;
  for (const auto& [solid, mat] : m.by_solid) {
    nlohmann::json e = mat;
    e["solid"] = solid;
    j["solids"].push_back(e);
  }
}

void to_json(nlohmann::json& j, const ModalResult& r) {
  j["fixed_dofs"] = r.num_fixed_dofs;
  j["free_dofs"] = r.num_free_dofs;
  j["mass_kg"] = r.total_mass;
  // The mass the free DOFs carry per direction (what CalculiX calls the total effective mass):
  // the effective mass fractions sum towards it, not towards 1, on a clamped part.
  j["free_mass_kg"] = {r.free_mass[0], r.free_mass[1], r.free_mass[2]};
  j["volume_m3"] = r.volume;
  j["modes"] = nlohmann::json::array();
  for (std::size_t m = 0; m < r.frequencies.size(); ++m) {
    const auto i = static_cast<Eigen::Index>(m);
    j["modes"].push_back({{"mode", m + 1},
                          {"frequency_hz", r.frequencies[m]},
                          {"eigenvalue", r.eigenvalues[m]},
                          {"effective_mass_fraction",
                           {r.effective_mass_fraction(i, 0), r.effective_mass_fraction(i, 1),
                            r.effective_mass_fraction(i, 2)}}});
  }
  j["solver"] = {{"order_s", r.order_seconds},
                 {"assemble_s", r.assemble_seconds},
                 {"factor_s", r.eigen.factor_seconds},
                 {"stiffness_nnz", r.stiffness_nnz},
                 {"factor_nnz", r.eigen.factor_nnz},
                 {"factor_bytes", r.eigen.factor_bytes},
                 {"shift", r.eigen.sigma},
                 {"max_residual", r.eigen.max_residual}};
  j["solver"]["method"] = r.eigen.method;
  if (!r.eigen.algorithm.empty()) j["solver"]["algorithm"] = r.eigen.algorithm;
  j["solver"]["reason"] = r.solver_reason;
  j["solver"]["setup_s"] = r.eigen.setup_seconds;
  j["solver"]["solve_s"] = r.eigen.solve_seconds;
  j["solver"]["iterations"] = r.eigen.iterations;
  j["solver"]["peak_memory_bytes"] = r.eigen.peak_memory_bytes;
  if (r.eigen.method == "iterative") {
    j["solver"]["peak_memory_after_assembly_bytes"] = r.eigen.peak_memory_assembly_bytes;
    j["solver"]["peak_memory_after_setup_bytes"] = r.eigen.peak_memory_setup_bytes;
  }
  j["solver"]["ranks"] = r.eigen.ranks;
}

void to_json(nlohmann::json& j, const ConvergenceRow& row) {
  j = {{"h", row.h},
       {"nodes", row.nodes},
       {"cells", row.cells},
       {"H_vol", row.h_vol},
       {"H_nbr", row.h_nbr},
       {"seconds", row.seconds},
       {"frequencies_hz", row.frequencies}};
}

void to_json(nlohmann::json& j, const ConvergenceStudy& s) {
  j["part"] = s.part;
  j["reference_hz"] = s.reference;
  j["rows"] = nlohmann::json::array();
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    nlohmann::json jr = s.rows[r];
    for (int i = 0; i < s.num_frequencies() && !s.reference.empty(); ++i)
      jr["relative_error"].push_back(s.error(r, i));
    j["rows"].push_back(jr);
  }
  for (int i = 0; i < s.num_frequencies(); ++i) {
    const double p = s.observed_order(s.rows.size() - 1, i);
    j["observed_order"].push_back(std::isnan(p) ? nlohmann::json() : nlohmann::json(p));
    j["monotone"].push_back(s.monotone(i));
  }
}

void to_json(nlohmann::json& j, const SurfaceReport& r) {
  const TriangleQuality& q = r.quality;
  j = {{"points", r.points},
       {"edge_points", r.edge_points},
       {"triangles", r.triangles},
       {"estimated_points", r.estimated_points},
       {"right_isosceles_share", q.right_isosceles_share},
       {"min_angle_deg", q.min_angle},
       {"max_angle_deg", q.max_angle},
       {"triangles_below_5deg", q.below_5},
       {"curvature_used", r.curvature_used},
       // Forced by the CAD model: the small angle is at a face corner sharper than 5° there.
       {"triangles_below_5deg_at_cad_corners_below_5deg", q.below_5_at_cad_corners},
       {"forcing_cad_corner_deg", {q.forcing_corner_min, q.forcing_corner_max}}};
  double volume = 0, total = 0;
  j["solids"] = nlohmann::json::array();
  for (const auto& c : r.checks) {
    volume += c.volume;
    j["solids"].push_back({{"id", c.solid},
                           {"triangles", c.triangles},
                           {"volume", c.volume},
                           {"closed", c.open_edges == 0 && c.nonmanifold_edges == 0},
                           {"touching_edges", c.touching_edges},
                           {"oriented", c.misoriented_edges == 0 && c.volume > 0},
                           {"self_intersects", c.self_intersects}});
  }
  j["mesh_volume"] = volume;
  j["stage_seconds"] = nlohmann::json::object();
  for (const auto& [name, s] : r.stage_seconds) {
    j["stage_seconds"][name] = s;
    total += s;
  }
  j["total_seconds"] = total;
}

void to_json(nlohmann::json& j, const Order2Report& r) {
  j = {{"edge_nodes", r.edge_nodes},
       {"boundary_nodes", r.boundary_nodes},
       {"curved_nodes", r.curved_nodes},
       {"projection_refused", r.projection_refused},
       {"max_offset", r.max_offset},
       {"bent_cells", r.bent_cells},
       {"straightened_cells", r.straightened_cells},
       {"hanging_placed", r.hanging_placed},
       {"hanging_kept", r.hanging_kept},
       {"nc_made_conformal", r.nc_made_conformal},
       {"nc_left_untied", r.nc_left_untied}};
  j["stages"] = nlohmann::json::array();
  for (const StageTime& t : r.stages)
    j["stages"].push_back({{"name", t.name}, {"seconds", t.seconds}});
  j["seconds"] = r.seconds();
}

}  // namespace hexfem
