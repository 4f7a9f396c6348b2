// The iterative path's distributed matrices (fem/iterative_solver.cpp): which nodes carry
// equations and where, and each rank's rows of K - σM and M in PETSc matrices (block size 3).
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <vector>

#include "fem/dof_layout.hpp"
#include "fem/material.hpp"
#include "fem/nc_ties.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Nodes of any element (corners and, at order 2, mid-edge nodes).
std::vector<std::uint8_t> element_node_mask(const MixedMesh& mesh);

// The nodes that carry equations (used by a cell, not fixed in all three components) in a
// Morton (Z-curve) order of their coordinates: neighbours stay close in memory, and cutting the
// order into contiguous ranges gives compact per-rank parts.
// Nodes tied to others (order-2 NC faces, fem/nc_ties.hpp) carry no equation either.
DofLayout make_layout(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                      const NodeTies& ties, int rank, int size);

// Typical K_ii / M_ii from the element matrices of a sample of cells (the same on every rank):
// the scale of the shift, the zero-eigenvalue floor and the spurious eigenvalue.
double stiffness_scale(const MixedMesh& mesh, const std::vector<const Material*>& cell_mat,
                       double length_scale);

// This rank's rows of K - σM (AIJ) and M (SBAIJ, its upper triangle).
struct Matrices {
  Mat K = nullptr, M = nullptr;
  ~Matrices() {
    MatDestroy(&K);
    MatDestroy(&M);
  }
};

// Assembles K - σM (positive definite also for a free structure) and M over this rank's cells.
// DOFs fixed on partly free nodes are decoupled, with K_ii / M_ii = λ_spurious.
// Returns the mass of the whole mesh; `volume` gets its volume.
double assemble(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed, const NodeTies& ties,
                const DofLayout& L, double length_scale, bool incompatible_hex,
                const std::vector<const Material*>& cell_mat, double sigma, double lambda_spurious,
                Matrices& mats, double& volume);

}  // namespace hexfem
