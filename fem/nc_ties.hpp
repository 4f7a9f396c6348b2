// Order 2 at a non-conformal quad face (a quad8 face of a hex20, wedge15 or pyramid13 against the
// two tri6 faces of the cells beyond): the triangles' shared diagonal has a mid-edge node that
// the quad8 has not. Left free, that node lets the face open along the diagonal (a crack; the
// mesh comes out too soft, frequencies below the converged ones: validation/solver.md §7). It is
// tied to the quad8's trace at the face point nearest to it (the centre on a parallelogram),
//   (there, u = -1/4 (u_1 + u_2 + u_3 + u_4) + 1/2 (u_12 + u_23 + u_34 + u_41)),
// so it carries no equation of its own. The traces still differ along the diagonal (by the
// quad8's cubic terms), a consistency error like order 1's, that vanishes with refinement.
#pragma once

#include <cstdint>
#include <vector>

#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

inline constexpr int kTieMasters = 8;
// Nodes an element can carry once its tied nodes are replaced by their masters (a tet10 with
// two tied nodes: 8 + 16).
inline constexpr int kMaxTiedElementNodes = 48;

struct NodeTies {
  std::vector<std::int32_t> slot;    // per node: its tie's index, -1 if not tied; empty: no tie
  std::vector<std::int32_t> master;  // kTieMasters per tie
  std::vector<double> weight;        // kTieMasters per tie
  long count = 0;
  long refused = 0;  // hanging nodes left free: fixed, or a master tied itself
  bool tied(std::int32_t v) const { return !slot.empty() && slot[v] >= 0; }
};

// The ties of an order-2 mesh's NC quad faces (mesh.nc_cell); none at order 1. A hanging node
// with a fixed component (the mask of select_fixed_dofs, may be empty) is left free.
NodeTies nc_face_ties(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed = {});

// The ties as the exporters' plain list (tied node, its masters and weights), for the .inp.
std::vector<NodeTie> node_tie_list(const NodeTies& ties);

// The nodes that carry an element's DOFs: its own (ids, n of them), each tied node replaced by
// its masters, no repeats. Writes them to `out` and C (n x count, row-major) with
// u_element = C u_out; returns the count, or -1 (out, C untouched) when no node is tied.
int tied_element_nodes(const NodeTies& ties, const std::int32_t* ids, int n, std::int32_t* out,
                       double* C);

// Element matrices on the nodes of tied_element_nodes: K' = (C ⊗ I3)ᵀ K (C ⊗ I3) (K 3n x 3n,
// DOF 3i+a) and m' = Cᵀ m C (m n x n); K' is 3k x 3k, m' k x k.
void tie_element_matrices(const double* C, int n, int k, const double* K, const double* m,
                          double* K_out, double* m_out);

// The tied nodes' displacements from their masters' (full nodal vector, 3 per node).
void fill_tied_nodes(const NodeTies& ties, double* u);

}  // namespace hexfem
