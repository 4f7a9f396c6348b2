// The algebraic multigrid of the iterative path, one configuration for both of its users: the
// V-cycle that preconditions LOBPCG (block_vcycle.hpp) and the CG solves of the Krylov-Schur
// fallback (krylov_schur.hpp).
#pragma once

#include <petscksp.h>

#include <vector>

#include "fem/iterative_settings.hpp"

namespace hexfem {

// GAMG (smoothed aggregation) on the KSP's operator with the settings' threshold, prolongator
// smoothing and coarse size; the near-null space comes from the matrix.
void configure_gamg(KSP ksp, const IterativeSettings& s);

// A's near-null space for the aggregation: the six rigid-body motions of its nodes, whose
// coordinates are given for this rank's rows (x y z per node, block size 3).
void set_rigid_body_near_null_space(Mat A, const std::vector<double>& local_coords);

// Frees what GAMG's Galerkin products (PtAP, the smoothed prolongators) keep for a later setup on
// new values (never done here): on 2 ranks at 1M DOF that is about 1.3 GB held through the solve.
void drop_galerkin_intermediates(PC pc);

}  // namespace hexfem
