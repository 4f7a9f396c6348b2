// Every tuning choice of the iterative eigensolver (iterative_solver.cpp) in one place, with
// what it was measured against (validation/solver.md §10). PETSC_OPTIONS in the environment
// overrides any of them at run time (e.g. PETSC_OPTIONS="-pc_gamg_threshold 0.02").
#pragma once

namespace hexfem {

struct IterativeSettings {
  // The convergence test on each Ritz pair (x M-normalized): |Kx - λMx| / (max(|λ|, floor)
  // sqrt(mass per DOF)), about |r|_{M^-1} / λ, dimensionless (lobpcg.cpp). The eigenvalue error
  // goes as its square over the relative gap to the next eigenvalue outside the block: 1e-5
  // gives frequencies within ~1e-11 of the direct path on the cantilevers (19 iterations at 305k
  // DOF, against 22 for 1e-6 and 17 for 3e-5), and stays under 1e-7 down to gaps of 0.1 %.
  double tolerance = 1e-5;
  // LOBPCG outer iterations (~30-40 needed where it converges; a cluster of modes across the
  // block's edge, as on a symmetric part, stalls it for good: then Krylov-Schur takes over).
  int max_iterations = 200;
  // ... unless it still converges steadily: while the rate of the last progress_window
  // iterations would reach the tolerance by max_iterations_progressing, it goes on (40mm_capot at
  // order 2, free: 232 iterations at a steady rate where the fallback took over 900 s).
  int progress_window = 20;
  int max_iterations_progressing = 1000;
  // The fallback: Krylov-Schur on (K - σM)^-1 M (shift-and-invert), each solve by CG with the
  // same GAMG; its own relative test on the transformed eigenvalues (no round-off floor as
  // LOBPCG's), and CG to a tighter tolerance than the eigen-residual it must resolve.
  bool krylov_schur_fallback = true;
  // LOBPCG gives up when no wanted pair has converged and its rate would need more than twice
  // this many iterations (lobpcg.hpp; 0: it runs to max_iterations). --solver auto sets it where
  // the direct path can take over (modal_solver.cpp).
  int stall_iterations = 0;
  double krylov_schur_tolerance = 1e-9;
  double cg_tolerance = 1e-11;
  int krylov_schur_max_iterations = 300;
  // The preconditioner is AMG on K - σM, σ = -shift_fraction * median(K_ii / M_ii): positive
  // definite for free structures, and close enough to K not to weaken it.
  double shift_fraction = 1e-8;
  // Eigenvalues below floor_fraction * median(K_ii / M_ii) are judged by an absolute residual
  // (rigid-body modes have λ ≈ 0, where a relative test can never pass).
  double floor_fraction = 1e-7;
  // A DOF fixed on a node whose other DOFs are free stays in the (block size 3) matrices,
  // decoupled, with K_ii / M_ii = spurious_factor * max(K_jj / M_jj): far above the wanted modes.
  double spurious_factor = 1e3;
  // LOBPCG block size; 0 = the number of modes wanted plus extra_block_columns (columns past
  // the wanted ones speed up the last wanted pairs and need not converge).
  int block_size = 0;
  int extra_block_columns = 2;
  // GAMG: smoothed aggregation with the six rigid-body modes as near-null space.
  double gamg_threshold = 0.01;  // drop tolerance of the aggregation graph
  int gamg_smooths = 1;          // prolongator smoothing steps (1 = smoothed aggregation)
  int gamg_coarse_eq_limit = 1000;
  // GAMG's hierarchy applied by fem/block_vcycle.cpp to the whole block at once (Chebyshev-Jacobi
  // smoothing, chebyshev_steps before and after the coarse correction, as GAMG's default
  // smoother); false: PETSc's own V-cycle, column by column.
  bool block_vcycle = true;
  int chebyshev_steps = 2;
  // Order 2: GAMG's hierarchy built on the order-1 space of the same mesh (P^T K P), with one
  // Chebyshev-Jacobi level on K above it (fem/p_multigrid.hpp); false: GAMG on K itself.
  bool p_multigrid = true;
  // The Chebyshev interval is [chebyshev_low, 1.1] x the largest eigenvalue of D⁻¹A per level.
  double chebyshev_low = 0.1;
};

}  // namespace hexfem
