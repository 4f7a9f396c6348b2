// JSON of the reports the CLI prints (nlohmann's to_json, found by argument-dependent lookup):
// one serialisation per report type, so `nlohmann::json j = report;` is the only way a command
// writes one. Mesher reports: mesher/mesh_reports.hpp; mesh measures: mesh_stats.hpp.
#pragma once

#include <nlohmann/json.hpp>

#include "app/convergence_table.hpp"
#include "fem/modal_solver.hpp"
#include "mesher/high_order_nodes.hpp"
#include "mesher/surface_pipeline.hpp"

namespace hexfem {

// Material (SI), DOF counts, mass, volume, the modes (frequency, eigenvalue, effective mass
// fractions) and the solver's figures.
void to_json(nlohmann::json& j, const Material& m);
// The material of every solid; with per-solid materials also "solids": [{solid, name, E, nu,
// rho}] for the solids that have their own.
void to_json(nlohmann::json& j, const SolidMaterials& m);
void to_json(nlohmann::json& j, const ModalResult& r);

// One convergence run, and the study with errors, observed orders and monotonicity.
void to_json(nlohmann::json& j, const ConvergenceRow& row);
void to_json(nlohmann::json& j, const ConvergenceStudy& s);

// The surface mesher's report: points, triangles, angles, checks per solid, time per stage.
void to_json(nlohmann::json& j, const SurfaceReport& r);

// Order 2: mid-edge nodes, curving onto the CAD, straightened cells, placed hanging nodes.
void to_json(nlohmann::json& j, const Order2Report& r);

}  // namespace hexfem
