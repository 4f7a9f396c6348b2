// Order 2 from an order-1 mesh: one node at the middle of every edge (shared edges get one node),
// the ones on the boundary moved onto the CAD geometry, and the local straightening of cells that
// curving would make invalid. The Jacobian check itself is the caller's (fem knows the elements;
// this layer does not).
#pragma once

#include <functional>

#include "mesher/mesh/mixed_mesh.hpp"
#include "mesher/stage_timer.hpp"

namespace hexfem {

struct Order2Report {
  long edge_nodes = 0;          // mid-edge nodes added
  long boundary_nodes = 0;      // of those, on boundary faces
  long curved_nodes = 0;        // boundary nodes the geometry moved off the straight midpoint
  long projection_refused = 0;  // boundary nodes left straight: the projection jumped too far
  double max_offset = 0;        // largest |node - midpoint| / edge length
  long bent_cells = 0;          // cells made valid by moving interior mid-edge nodes instead
  long bent_nodes = 0;          // interior mid-edge nodes moved for them
  long straightened_cells = 0;  // cells made valid by setting their curved nodes back (partly)
  long straightened_nodes = 0;
  long hanging_placed = 0;        // NC faces' mid-diagonal nodes moved onto their quad's surface
  long hanging_kept = 0;          // left where they were: a cell around them would have degraded
  long nc_made_conformal = 0;     // NC faces made conformal instead (app/part_modal.cpp)
  long nc_left_untied = 0;        // NC faces whose hanging node stays free (no pyramids asked for)
  std::vector<StageTime> stages;  // the caller's steps, timed (app/part_modal.cpp)
  double seconds() const {        // the steps' wall time in all
    double sum = 0;
    for (const StageTime& t : stages) sum += t.seconds;
    return sum;
  }
};

// Where the mid-edge node of boundary edge (a, b) goes: the edge lies on CAD faces face1 and
// face2 of the boundary faces beside it (equal inside a face, different on a CAD edge). Called
// on all threads at once.
using MidEdgeProjector = std::function<Vec3(const Vec3& a, const Vec3& b, int face1, int face2)>;

// Makes `mesh` order 2 (mesh.order, cell_edge_nodes, bface_edge_nodes, new nodes appended).
// Without a projector every node stays at its edge's midpoint (straight elements). A projected
// point farther than half the edge length from the midpoint is refused (kept straight).
void add_mid_edge_nodes(MixedMesh& mesh, const MidEdgeProjector& project = {},
                        Order2Report* report = nullptr);

// Cell c's worst Jacobian: min det J / max det J over its sample points (<= 0: inverted).
using CellJacobianRatio = std::function<double(const MixedMesh& mesh, std::size_t c)>;

// Curving a boundary edge can invert a thin cell behind it. Before anything is straightened, each
// cell whose ratio is below `min_ratio` has its interior mid-edge nodes (not on the boundary)
// moved, by a coordinate search that raises the worst ratio of the cells around them, so that
// the cell follows the curved boundary. The corners and the boundary nodes stay where they are.
// A cell that cannot be brought to min_ratio this way has its moves undone (and is left to
// straighten_invalid_cells). Deterministic: the cells in order, a fixed search pattern. The
// search itself uses `search_ratio` (a cheaper check, e.g. at fewer points); `ratio` decides.
// `ratios`, if given, is set to every cell's ratio as the mesh is left (for the steps below).
void bend_interior_nodes(MixedMesh& mesh, const CellJacobianRatio& ratio,
                         const CellJacobianRatio& search_ratio, double min_ratio,
                         Order2Report* report = nullptr, std::vector<double>* ratios = nullptr);

// Every cell whose ratio is below `min_ratio` gets its curved nodes set back towards their
// edges' midpoints, by the first of 10 %, 20 %, ... 100 % of their offset that brings it to
// min_ratio (its neighbours' shared edges move with them), while that raises its ratio;
// repeated until no cell changes. Throws hexfem::Error naming the first cell still inverted
// afterwards. `ratios`, if it has one entry per cell, is taken as every cell's ratio as the mesh
// stands (as bend_interior_nodes leaves it), and is left so.
void straighten_invalid_cells(MixedMesh& mesh, const CellJacobianRatio& ratio, double min_ratio,
                              Order2Report* report = nullptr,
                              std::vector<double>* ratios = nullptr);

// At an NC quad face the triangles' diagonal has a mid-edge node the quad does not have. Straight,
// it lies off the quad8's curved (twisted) surface: the solver cannot tie it to the quad's trace
// there, so the face opens, and the cells on both sides overlap. Each such node is moved to the
// quad8's point nearest to it, unless a cell around it would then fall below min_ratio (or below
// its own ratio, if that was lower). Nodes on a side of another NC quad stay (that quad's own
// tie depends on them). Call after straighten_invalid_cells. `ratios` as there.
void place_hanging_nodes_on_quads(MixedMesh& mesh, const CellJacobianRatio& ratio, double min_ratio,
                                  Order2Report* report = nullptr,
                                  std::vector<double>* ratios = nullptr);

}  // namespace hexfem
