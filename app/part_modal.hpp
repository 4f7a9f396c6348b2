// The whole chain in one process: CAD part -> hex-dominant mesh -> modal analysis.
// Shared by `hexfem modal part.step` and `hexfem converge`.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "fem/modal_solver.hpp"
#include "mesher/high_order_nodes.hpp"
#include "mesher/pipeline.hpp"

namespace hexfem {

struct PartModalResult {
  MixedMesh mesh;
  MeshReport mesh_report;  // mesh_report.stats: the mesh's measures
  ModalResult modal;
  double mesh_seconds = 0, solve_seconds = 0;  // mesh_seconds includes the order-2 nodes
  double mesh_peak_bytes = 0;  // the process's peak resident memory when the mesh was done
  Order2Report order2;         // order 2 only
};

// True for the CAD extensions hexfem reads (.step .stp .iges .igs .brep .rle).
bool is_cad_file(const std::filesystem::path& path);

// Checks that every face id named in --fix specs ("face:3,7[@xyz]") exists in the part, so a
// typo is reported before any meshing. Throws hexfem::Error naming the missing id.
void check_fixed_faces_exist(const CadModel& cad, const std::vector<std::string>& fix);

// Meshes the part (lengths in mm, so options.length_scale is set to 1e-3 m/mm) and solves.
// With a non-empty fix list, a result with rigid-body modes left (the fixed set does not hold
// the part) is an error, not a silently free analysis; so is a mesh whose volume is more than
// 10 % off the CAD's, unless `force`.
PartModalResult run_part_modal(const CadModel& cad, const MeshOptions& mesh_options,
                               ModalOptions modal_options, bool force = false, int order = 1);

// Makes an order-1 mesh order 2: mid-edge nodes, the boundary ones on the CAD geometry when
// `cad` is given; a cell whose curving would leave min/max det J below 1e-4 first has its
// interior mid-edge nodes moved to follow the boundary, and is straightened only if that fails.
// With `allow_pyramids` false (--no-pyramids) the NC faces whose hanging node cannot be tied stay
// as they are (Order2Report::nc_left_untied counts them) instead of being made conformal with a
// pyramid and tets.
Order2Report raise_to_order2(MixedMesh& mesh, const CadModel* cad, bool allow_pyramids = true);

// raise_to_order2 on a part just meshed (mesh_part's `report`), and the report made to describe
// the mesh that results: its measures again where NC faces were made conformal, the curved
// cells' volume against the CAD's (and the volume warning from it), a warning for hanging nodes
// left free. h: the size it was meshed at.
Order2Report raise_part_to_order2(MixedMesh& mesh, const CadModel& cad, bool allow_pyramids,
                                  double h, MeshReport& report);

// The options to write `mesh` to `path`. At order 2 with NC faces the hanging mid-diagonal nodes
// are tied as hexfem's solver ties them (fem/nc_ties.hpp): an .inp gets the ties as *EQUATION;
// a .msh or .vtu cannot carry them, and a warning (added to `warnings`) says the nodes are free
// there and names the ways out.
MeshWriteOptions mesh_write_options(const MixedMesh& mesh, const std::filesystem::path& path,
                                    bool binary, std::vector<std::string>* warnings);

// One line naming the element formulations used at this order.
std::string element_formulations(int order, bool incompatible_hex);

// The --hex8 option: "incompatible" (Wilson-Taylor bubbles, accurate in bending; the default)
// -> true, "full" (2x2x2, = CalculiX C3D8) -> false; anything else is an error.
bool incompatible_hex_from_option(const std::string& value);

}  // namespace hexfem
