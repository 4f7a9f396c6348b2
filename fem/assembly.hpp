// Global stiffness and consistent mass of a mixed mesh (free DOFs only, Dirichlet DOFs
// eliminated), isotropic linear elasticity.
#pragma once

#include <Eigen/SparseCore>

#include "fem/boundary.hpp"
#include "fem/material.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// 64-bit indices so CHOLMOD runs its long-integer version (factors of 1M-DOF meshes can pass
// 2^31 entries).
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, long>;

struct SystemMatrices {
  // Lower triangles (row >= column) of K and M; both share one sparsity pattern.
  SparseMatrix K, M;
  double mass = 0;    // Σ of all consistent-mass entries / 3 = ρ·V (fixed DOFs included)
  double volume = 0;  // Σ ∫ dV over the cells
};

// Assembles K and M, each cell with the material of its solid (mesh.cell_solid); coordinates
// are multiplied by `length_scale` (e.g. 1e-3 for a mesh in mm with SI material). Throws
// hexfem::Error if a cell has a non-positive Jacobian at a quadrature point, or for an invalid
// material. Runs over the cells in parallel when OpenMP is available. incompatible_hex: hexes get
// the incompatible-modes stiffness (hex8_incompatible.hpp) instead of the fully integrated one (=
// CalculiX C3D8).
SystemMatrices assemble_system(const MixedMesh& mesh, const SolidMaterials& mats,
                               const DofMap& dofs, double length_scale = 1.0,
                               bool incompatible_hex = false);

// The material of each cell: table[cell_solid[c]] of SolidMaterials::table (base for a mesh
// without solid ids).
std::vector<const Material*> cell_materials(const MixedMesh& mesh, const SolidMaterials& mats);

// The node adjacency (nodes sharing a cell, itself excluded) as CSR: neighbours of node i are
// adj[ptr[i] .. ptr[i+1]), sorted. Used for the matrix pattern and for fill-reducing orders.
struct NodeGraph {
  std::vector<long> ptr;
  std::vector<std::int32_t> adj;
};
// With ties, a tied node's cells couple its masters instead (the tied node has no neighbour).
NodeGraph node_graph(const MixedMesh& mesh, const NodeTies* ties = nullptr);

}  // namespace hexfem
