// The order-1 space of an order-2 mesh as a coarse level (p-multigrid) for the iterative path's
// preconditioner. GAMG's smoothed aggregation handles order-1 stiffness well and order-2 poorly:
// on the same tie_rod mesh (h 12, free, 8 modes) LOBPCG took 36 iterations at order 1 and 149 at
// order 2 with GAMG on the order-2 matrix (validation/solver.md §16). So GAMG runs on P^T K P,
// and one Chebyshev-Jacobi smoothed level on K sits above it (BlockVcycle::add_finer_level).
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <vector>

#include "fem/dof_layout.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct OrderOneCoarse {
  Mat P = nullptr;  // the layout's DOFs -> the vertices' DOFs (order-1 interpolation)
  Mat A = nullptr;  // P^T K P, with the vertices' rigid-body motions as near-null space
  OrderOneCoarse() = default;
  OrderOneCoarse(const OrderOneCoarse&) = delete;
  OrderOneCoarse& operator=(const OrderOneCoarse&) = delete;
  ~OrderOneCoarse();
};

// P and A for an order-2 mesh. The vertices are the layout's corner nodes, in the layout's order
// and on the rank that owns them. A vertex DOF is its own coarse DOF; a free mid-edge DOF is the
// mean of its edge's two corner DOFs (a fixed or absent corner counts as 0); a fixed DOF (kept
// decoupled in K) gets nothing from the coarse level.
void make_order_one_coarse(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                           const DofLayout& L, double length_scale, Mat K, OrderOneCoarse& out);

}  // namespace hexfem
