// One V-cycle of a set-up PETSc multigrid preconditioner (GAMG) applied to a block of vectors at
// once. PETSc 3.18 applies a multigrid PC to a block (PCMatApply) column by column in its
// smoothers, so every column reads the level matrices again; here each level's Chebyshev-Jacobi
// smoothing, residual and transfers are block products (row_block_product.hpp) on blocks stored
// row by row, which read a level matrix once for the whole block (validation/solver.md §10).
// The hierarchy (aggregates, prolongators, Galerkin operators) and the coarse solver stay GAMG's.
#pragma once

#include <petscksp.h>

#include <memory>
#include <vector>

#include "fem/row_block_product.hpp"

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

  // A level above the finest: operator A (its rows are apply()'s from now on), interpolation P
  // from the old finest level, smoothed as the others (fem/p_multigrid.hpp: order 2 over GAMG's
  // order-1 hierarchy).
  void add_finer_level(Mat A, Mat P);

  // out = one V-cycle applied to each column of in (dense matrices with the fine level's rows).
  void apply(Mat in, Mat out);
  // The same on one vector (the CG solves of the Krylov-Schur fallback).
  void apply(Vec in, Vec out);
  // out = A in, A the finest level's operator, through the cycle's idle finest-level blocks.
  void multiply_finest(Mat in, Mat out);

 private:
  struct Level {
    Mat A = nullptr;               // the level operator (GAMG's)
    Mat P = nullptr;               // interpolation from the next coarser level (none on level 0)
    std::vector<double> inv_diag;  // Jacobi, this rank's rows
    double emin = 0, emax = 0;
    // For the current column count k: products and work blocks, rows of k values (kept from one
    // cycle to the next: allocating them on every call cost 13 % of the solve at 1M DOF).
    std::unique_ptr<RowBlockProduct> a, p;  // A, and P (from the coarser level)
    std::vector<double> b, x, r, d;         // right-hand side, solution, residual, step
  };
  void set_up_smoother(Level& L);  // Jacobi diagonal and Chebyshev interval of L.A
  void prepare(int k);
  void load_rhs(Level& L);  // L.r = L.b (the finest level's from rhs_)
  void cycle(int l);
  void smooth(Level& L, bool zero_guess);
  std::vector<Level> levels_;  // 0 = coarsest
  KSP coarse_ = nullptr;
  Mat rhs_ = nullptr;                            // apply()'s input while it runs
  Mat coarse_b_ = nullptr, coarse_x_ = nullptr;  // level 0's b and x as PETSc dense blocks
  int steps_;
  double lo_, hi_;  // the Chebyshev interval over the largest eigenvalue of D⁻¹A
  int k_ = 0;       // the column count the work is made for
};

}  // namespace hexfem
