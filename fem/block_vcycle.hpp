// One V-cycle of a set-up PETSc multigrid preconditioner (GAMG) applied to a block of vectors at
// once. PETSc 3.18 applies a multigrid PC to a block (PCMatApply) column by column in its
// smoothers, so every column reads the level matrices again; here each level's Chebyshev-Jacobi
// smoothing, residual and transfers are block products (MatMatMult), which read a level matrix
// once for the whole block: about 3x less time per column on the fine level (measured at 94.5k
// DOF, validation/solver.md §10). The hierarchy (aggregates, prolongators, Galerkin operators)
// and the coarse solver stay GAMG's.
#pragma once

#include <petscksp.h>

#include <vector>

namespace hexfem {

class BlockVcycle {
 public:
  // pc: a PCMG/PCGAMG after PCSetUp. chebyshev_steps: smoothing steps before and after the
  // coarse correction on each level; the Chebyshev interval is [lo, hi] * the largest eigenvalue
  // of D⁻¹A (estimated by Lanczos), as PETSc's default for GAMG levels.
  BlockVcycle(PC pc, int chebyshev_steps, double lo = 0.1, double hi = 1.1);
  ~BlockVcycle();
  BlockVcycle(const BlockVcycle&) = delete;
  BlockVcycle& operator=(const BlockVcycle&) = delete;

  // out = one V-cycle applied to each column of in (dense matrices with the fine level's rows).
  void apply(Mat in, Mat out);

 private:
  struct Level {
    Mat A = nullptr;         // the level operator (GAMG's)
    Mat P = nullptr;         // interpolation from the next coarser level (none on level 0)
    Vec inv_diag = nullptr;  // Jacobi
    double emin = 0, emax = 0;
    // Work blocks of this level's rows, kept from one cycle to the next (allocating and
    // page-faulting them on every call cost 13 % of the solve at 1M DOF). Products attached once:
    // ad = A d, ax = A x, e = P (coarser x), and the coarser level's b = Pᵀ r.
    Mat b = nullptr, x = nullptr, r = nullptr, d = nullptr, ad = nullptr, ax = nullptr, e = nullptr;
  };
  void prepare(PetscInt ncols);
  void release();
  void cycle(int l);
  void smooth(Level& L, bool zero_guess);
  std::vector<Level> levels_;  // 0 = coarsest
  KSP coarse_ = nullptr;
  int steps_;
  PetscInt ncols_ = 0;  // the column count the work blocks are made for
};

}  // namespace hexfem
