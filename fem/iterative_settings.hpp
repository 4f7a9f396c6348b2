// Every tuning choice of the iterative eigensolver (iterative_solver.cpp) in one place, with
// what it was measured against (validation/solver.md §10). PETSC_OPTIONS in the environment
// overrides any of them at run time (e.g. PETSC_OPTIONS="-pc_gamg_threshold 0.02").
#pragma once

namespace hexfem {

struct IterativeSettings {
  // SLEPc's convergence test on each Ritz pair: |Kx - λMx| / max(|λ|, floor) / |x|_M... (see
  // iterative_solver.cpp); 1e-8 makes the eigenvalues agree with the direct path to ~1e-12.
  double tolerance = 1e-8;
  int max_iterations = 1000;  // LOBPCG outer iterations (~30-40 needed at any size)
  // The preconditioner is AMG on K - σM, σ = -shift_fraction * median(K_ii / M_ii): positive
  // definite for free structures, and close enough to K not to weaken it.
  double shift_fraction = 1e-8;
  // Eigenvalues below floor_fraction * median(K_ii / M_ii) are judged by an absolute residual
  // (rigid-body modes have λ ≈ 0, where a relative test can never pass).
  double floor_fraction = 1e-7;
  // A DOF fixed on a node whose other DOFs are free stays in the (block size 3) matrices,
  // decoupled, with K_ii / M_ii = spurious_factor * max(K_jj / M_jj): far above the wanted modes.
  double spurious_factor = 1e3;
  // LOBPCG block size; 0 = the number of modes wanted.
  int block_size = 0;
  // GAMG: smoothed aggregation with the six rigid-body modes as near-null space.
  double gamg_threshold = 0.01;  // drop tolerance of the aggregation graph
  int gamg_smooths = 1;          // prolongator smoothing steps (1 = smoothed aggregation)
  int gamg_coarse_eq_limit = 1000;
};

}  // namespace hexfem
