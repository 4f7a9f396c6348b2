// The paper's mesh measures (H_nbr, H_vol, Q, NC) and validity checks, for `hexfem stats`.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// The volume of the cells of one CAD solid (MixedMesh::cell_solid).
struct SolidVolume {
  std::int32_t solid = 0;
  double volume = 0;
};

struct MeshStats {
  int order = 1;  // the mesh's; the measures are of its corners (hexfem stats puts the curved
                  // cells' volume and validity in `volume` and `inverted` at order 2)
  std::size_t num_nodes = 0;
  std::array<std::size_t, kNumCellKinds> cells_per_kind{};  // indexed by CellKind
  std::size_t num_cells = 0;
  std::size_t num_boundary_faces = 0;  // stored boundary triangles + quads
  double h_nbr = 0;                    // % of cells that are hexes
  double h_vol = 0;                    // % of volume in hexes
  double q_mean = 0;                   // mean over hexes of the min corner scaled Jacobian
  double q_min = 0;                    // min over hexes (0 when there is no hex)
  std::array<double, kNumCellKinds> min_sj_per_kind{};  // 0 when the kind is absent
  std::size_t inverted = 0;                             // cells with a corner Jacobian <= 0
  std::size_t degenerate = 0;  // not inverted, min scaled Jacobian < kDegenerateScaledJacobian
  std::size_t interior_quads = 0;
  std::size_t nonconformal_quads = 0;
  double nc_percent = 0;                   // % of interior quad faces that are NC
  std::size_t boundary_faces_derived = 0;  // cell faces on the boundary
  std::size_t open_boundary_edges = 0;     // boundary edges in an odd number of faces
  bool watertight = false;
  double volume = 0;
  std::vector<SolidVolume> solid_volumes;  // per solid id, ascending (of the corners, as volume)
};

MeshStats compute_stats(const MixedMesh& mesh);
// The same from sorted_cell_faces(mesh) (face_keys.hpp), for a caller that has them already.
MeshStats compute_stats(const MixedMesh& mesh, const std::vector<CellFaceRef>& faces);

// Sums cell_volume (one per cell) by the cells' solids, in cell order; ascending solid ids.
std::vector<SolidVolume> volume_by_solid(const MixedMesh& mesh,
                                         const std::vector<double>& cell_volume);

// The same, as JSON (keys as the field names, per-kind maps keyed by kind_name()).
void to_json(nlohmann::json& j, const MeshStats& s);  // `nlohmann::json j = stats;`

// A short human-readable report (one quantity per line).
std::string stats_to_text(const MeshStats& s);

}  // namespace hexfem
