// The iterative path's fallback when LOBPCG fails (iterative_solver.cpp): SLEPc's Krylov-Schur on
// (K - σM)⁻¹M (shift-and-invert), each solve by CG with LOBPCG's own block V-cycle (at order 2
// the p-multigrid; solver.md §16, §17), or with PETSc's GAMG on K without one. Slower than LOBPCG
// where both converge (49.5 s against 20.9 s at 94.5k DOF, solver.md §10), but it has no block edge
// for a cluster of modes to straddle.
#pragma once

#include <petscksp.h>
#include <slepceps.h>

#include <functional>
#include <string>
#include <vector>

#include "fem/iterative_settings.hpp"

namespace hexfem {

struct KrylovSchurRun {
  std::string failure;  // empty on success, else a one-line error with the residual reached
  long iterations = 0;
  double setup_seconds = 0;
};

// The nev lowest modes of K x = λ M x (K positive definite), B-orthogonal to `deflation`, into
// `eps` (created and destroyed by the caller, which reads the eigenpairs from it). n: the DOF
// count, for the message. PETSc options with the prefix "ks_" tune it.
// precondition(x, y): y = B x for CG, a symmetric positive definite approximation of K⁻¹ (the
// LOBPCG V-cycle); none: PETSc's GAMG on K.
using VectorPreconditioner = std::function<void(Vec, Vec)>;
KrylovSchurRun krylov_schur(EPS eps, Mat K, Mat M, std::vector<Vec>& deflation, int nev,
                            const IterativeSettings& s, long n,
                            const VectorPreconditioner& precondition = {});

}  // namespace hexfem
