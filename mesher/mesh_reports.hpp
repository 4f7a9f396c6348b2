// The mesher's reports as JSON (`nlohmann::json j = report;`) and as text: the paper's table row
// (vertices, elements per kind, H_nbr, H_vol, Q, NC, inverted), the volume error and the time per
// stage, one quantity per line.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "mesher/pipeline.hpp"
#include "mesher/volume_pipeline.hpp"

namespace hexfem {

void to_json(nlohmann::json& j, const VolumeReport& r);
void to_json(nlohmann::json& j, const MeshReport& r);
std::string volume_report_text(const VolumeReport& r);
std::string mesh_report_text(const MeshReport& r);
// "18, volume error per solid -1.8 % (solid 7) to +0.1 % (solid 2)"; empty for one solid.
std::string solid_volume_range(const std::vector<SolidVolumeError>& solids);

}  // namespace hexfem
