// The modal options shared by `hexfem modal` and `hexfem converge`, declared and validated once.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "fem/modal_solver.hpp"
#include "mesher/pipeline.hpp"

namespace hexfem {

struct ModalCliOptions {
  std::vector<std::string> fix;
  // --material, repeatable: one name for every solid (default steel), and solid:IDS=NAME or
  // solid:IDS=E,nu,rho (SI) for some solids (parse_materials).
  std::vector<std::string> materials;
  double E = 0, nu = 0, rho = 0;  // used only when given (see the options below)
  int modes = 10;
  std::string hex8 = "incompatible";
  std::string solver = "auto";  // --solver direct|iterative|auto
  bool force = false;
  bool conformal = false;            // --conformal: CAD input meshed with no NC face
  std::vector<std::string> size_at;  // --size-at, CAD input: local sizes (parse_size_at)
  // Element order: 2 by default for a CAD part (validation/order2.md section 4: it reaches an
  // accurate frequency sooner); a mesh file is solved at its own order unless --order is given.
  int order = 2;
  // --curvature, CAD input: elements per turn on curved edges and faces; not given
  // (curvature_given) is the order's default: kOrder2Curvature at order 2, none at order 1.
  int curvature = 0;
  // --relax-points, CAD input: lattice relaxation sweeps of the interior points
  // (volume_points.hpp); -1 (not given) is none, unlike `mesh` (30): more hexes, but at order 2
  // the sphere's error doubles at equal DOF (validation/volume.md, "Relaxation and edge spacing
  // by default").
  int relax_points = -1;
  // --coherent-first, CAD input: the fronts of box-like walls first (volume_points.hpp); off
  // here, unlike `mesh`: the steel part at h = 2, order 2, f1 +0.086 % -> +0.150 % with it
  // (validation/volume.md, "Coherent walls first").
  bool coherent_first = false;
  // --align-opposite T, CAD input: the faces of walls up to T sizes thick packed from the same
  // points (surface_points.hpp); -1 (not given) is the mesher's default (2).
  double align_opposite = -1;
  // --no-pyramids, CAD input: the mesher makes no pyramids (quad faces against two triangles
  // stay NC); at order 2 such a face is tied (fem/nc_ties.hpp).
  bool no_pyramids = false;
  // --no-edge-spacing-size, CAD input: edge points sized by the size field, not by the spacing
  // their edges got (surface_pipeline.hpp).
  bool no_edge_spacing_size = false;
  // --glue, CAD input: solids that touch or overlap fragmented into a bonded assembly.
  bool glue = false;
  // --singular-size F, CAD input: size at the singular edges (re-entrant edges and the rim of
  // the clamped faces, mesher/singular_edges.hpp) as a fraction of h; 0 is none. Not given
  // (singular_size_given): the re-entrant edges alone at kOrder2ReentrantSize at order 2, none
  // at order 1 (validation/order2.md, "Graded towards the singular edges" and "Re-entrant edges
  // graded by default").
  double singular_size = 0;
  // Options whose absence means a default: asked with given() (a typed -1 is not "not given").
  CLI::Option* curvature_given = nullptr;
  CLI::Option* singular_size_given = nullptr;
  CLI::Option* order_given = nullptr;
  CLI::Option* hex8_given = nullptr;
  CLI::Option *E_given = nullptr, *nu_given = nullptr, *rho_given = nullptr;
};

// True when the option was on the command line.
inline bool given(const CLI::Option* option) {
  return option && option->count() > 0;
}

// Declares --fix --material --E --nu --rho --modes --hex8 --solver --force on `sub`; `o.modes`
// holds the default number of modes.
void add_modal_options(CLI::App& sub, ModalCliOptions& o);

// The --material values: at most one plain name (every solid; steel when none), then
// "solid:IDS=NAME" or "solid:IDS=E,nu,rho" (Pa, -, kg/m^3) with IDS a list of ids and ranges
// ("1,4-6"). --E, --nu and --rho (non-null when given) modify the plain name's material.
// Throws hexfem::Error naming the bad value.
SolidMaterials parse_materials(const std::vector<std::string>& specs, const double* E,
                               const double* nu, const double* rho);

// "'steel'", or with per-solid materials "'steel'; solids 2, 5: 'aluminium'" (solids of the same
// material together), for the text reports.
std::string material_summary(const SolidMaterials& m);

// A material given to a solid the CAD model does not have: a one-line error before any meshing.
void check_material_solids(const SolidMaterials& m, const CadModel& cad);

// Checks every value (material and its overrides finite and physical, --modes >= 1, --hex8, the
// syntax of each --fix) and returns the solver's options (length_scale left at 1).
ModalOptions modal_options_from(const ModalCliOptions& o);

// At order 2 a CAD part is meshed by default with this curvature bound (elements per turn), never
// finer than kOrder2CurvatureMinRatio * h. The steel part's R3 fillet, where the bending stress
// peaks, otherwise holds most of the error at h = 2 (f1 +0.176 % -> +0.095 % for 26 % more nodes;
// validation/order2.md section 3); the floor keeps parts with many small fillets from growing
// more than a few times in DOF.
inline constexpr int kOrder2Curvature = 12;
inline constexpr double kOrder2CurvatureMinRatio = 0.5;
// Size at re-entrant edges, a fraction of h, for a CAD part at order 2 without --singular-size:
// there the fields go like r^0.5 and every uniform mesh converges near order 1; graded, the
// housing gehause_rohteil reaches the same error with about half the DOF. The rim of a clamped
// face is not graded by default: on the steel part it cost DOF and no error (order2.md).
inline constexpr double kOrder2ReentrantSize = 0.5;

// The CAD faces a set of --fix specs clamps (all three components): the faces named by face:ID,
// and the faces whose bounding box lies in the region of a coordinate spec. Group specs name
// mesh groups, not CAD faces: none.
std::vector<int> clamped_cad_faces(const CadModel& cad, const std::vector<std::string>& fix);

// The edges graded towards their singular fields, each list sorted: with --singular-size F > 0
// the re-entrant edges and the rim of the clamped faces at F h; without it, at order 2, the
// re-entrant edges alone at kOrder2ReentrantSize h; else none. `note` says so in one phrase for
// the reports ("" when none). Throws hexfem::Error on a --singular-size outside [0, 1].
struct GradedEdges {
  std::vector<int> reentrant, rim;
  double fraction = 0;
  bool by_default = false;  // --singular-size not given: the order's default
  std::string note() const;
};
GradedEdges singular_edges_graded(const ModalCliOptions& o, const CadModel& cad);

// The mesh options of a CAD part at size h from the shared options: --size-at, --conformal,
// --relax-points, --curvature (or the order's default) and the edges --singular-size grades
// (singular_edges_graded, found once for every h). Throws hexfem::Error on a bad --size-at or
// --curvature.
MeshOptions cad_mesh_options(const ModalCliOptions& o, double h, const GradedEdges& graded);

// --hex8 chooses the order-1 hexahedron; given for an order-2 solve it would be ignored in
// silence, so it is an error naming --order 1. Throws hexfem::Error.
void check_hex8_for_order(const ModalCliOptions& o, bool order2);

}  // namespace hexfem
