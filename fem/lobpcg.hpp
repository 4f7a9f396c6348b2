// Block LOBPCG (Knyazev 2001) for the lowest eigenpairs of A x = λ B x, A and B symmetric
// positive definite PETSc matrices, preconditioned by a block operator (one AMG V-cycle). Written
// for the iterative path (iterative_solver.cpp) because SLEPc 3.18's LOBPCG recomputes A and B
// on the whole 3-block basis every iteration (about 40 + 40 products for 10 modes, against the
// 10 + 10 new ones this one does): the basis' products are updated by the same linear
// combinations as the basis, and refreshed once when every pair looks converged.
//
// Robustness (Duersch et al. 2018, "A robust and efficient implementation of LOBPCG"): the new
// directions are B-orthogonalized against the iterate, each block is orthonormalized by an
// eigendecomposition of its Gram matrix that drops directions below round-off (SVQB, Stathopoulos
// & Wu 2002), and the Rayleigh-Ritz step does the same on the whole basis. Converged wanted pairs
// are soft-locked (kept in the basis, no longer preconditioned). Every rank takes the small dense
// decisions from rank 0's numbers, so the iteration is the same for any number of ranks up to
// the order of sums.
#pragma once

#include <petscksp.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace hexfem {

struct LobpcgProblem {
  Mat A = nullptr;  // symmetric positive definite
  Mat B = nullptr;  // symmetric positive definite
  // Applies T ≈ A⁻¹ to each column of a dense block (out = T in).
  std::function<void(Mat in, Mat out)> precondition;
  // Computes out = A in on dense blocks when set (a faster product than PETSc's; else MatProduct).
  std::function<void(Mat in, Mat out)> multiply_a;
  std::vector<Vec> constraints;  // B-orthonormal; the modes are sought B-orthogonal to them
};

struct LobpcgOptions {
  int nev = 10;
  int block = 0;  // columns of the iterate (>= nev; 0 = nev); the extra ones only help
  double tolerance = 1e-6;
  int max_iterations = 200;
  // Past max_iterations it goes on while it still converges steadily: the largest error of the
  // wanted pairs fell by 10 % or more over the last progress_window iterations, and at that rate
  // it would meet the tolerance by max_iterations_progressing. A thin part converges linearly
  // but slowly; a stall, or a tolerance below round-off, does not move.
  int progress_window = 20;
  int max_iterations_progressing = 200;
  // Give up ("stalled") while no wanted pair has converged, as soon as a window's rate would need
  // more than twice this many iterations to converge them all, or after this many when no rate
  // is known yet (0: never). A run whose rate ends it by twice this many goes on past it.
  int stall_iterations = 0;
  // Convergence of a pair (x B-normalized): |Ax - λBx| / (max(|λ|, floor) sqrt(mass_per_dof))
  // < tolerance (iterative_solver.cpp sets it from IterativeSettings, 1e-5).
  double floor = 0, mass_per_dof = 1;
  std::function<void(int iteration, int converged, double worst)> monitor;  // may be empty
};

struct LobpcgResult {
  Eigen::VectorXd values;   // the nev lowest, ascending
  Eigen::MatrixXd vectors;  // this rank's rows x nev, B-orthonormal
  int iterations = 0;
  int converged = 0;    // wanted pairs below the tolerance at the end
  double worst = 0;     // largest error estimate among the wanted pairs at the end
  std::string failure;  // empty on success, else "did not converge" or "broke down: why"
};

LobpcgResult lobpcg(const LobpcgProblem& problem, const LobpcgOptions& options);

}  // namespace hexfem
