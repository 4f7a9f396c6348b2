#include "fem/lobpcg.hpp"

#include <petscblaslapack.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>

#include "fem/petsc_env.hpp"

namespace hexfem {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// out = U C + beta out on this rank's rows (BLAS: the tall blocks are the bulk of the dense work).
void combine(const MatrixXd& U, const MatrixXd& C, double beta, MatrixXd& out) {
  if (beta == 0) out.resize(U.rows(), C.cols());
  if (out.size() == 0) return;
  if (U.cols() == 0) {
    out *= beta;
    return;
  }
  const PetscBLASInt m = static_cast<PetscBLASInt>(U.rows()),
                     n = static_cast<PetscBLASInt>(C.cols()),
                     k = static_cast<PetscBLASInt>(U.cols());
  const double one = 1;
  BLASgemm_("N", "N", &m, &n, &k, &one, U.data(), &m, C.data(), &k, &beta, out.data(), &m);
}

// Uᵀ V over all ranks; every rank gets rank 0's copy of the sum (bitwise the same decisions).
MatrixXd inner(const MatrixXd& U, const MatrixXd& V) {
  MatrixXd local = MatrixXd::Zero(U.cols(), V.cols()), sum(U.cols(), V.cols());
  if (U.rows() > 0 && local.size() > 0) {
    const PetscBLASInt m = static_cast<PetscBLASInt>(U.cols()),
                       n = static_cast<PetscBLASInt>(V.cols()),
                       k = static_cast<PetscBLASInt>(U.rows());
    const double one = 1, zero = 0;
    BLASgemm_("T", "N", &m, &n, &k, &one, U.data(), &k, V.data(), &k, &zero, local.data(), &m);
  }
  if (local.size() == 0) return sum;
  MPI_Allreduce(local.data(), sum.data(), static_cast<int>(sum.size()), MPI_DOUBLE, MPI_SUM,
                PETSC_COMM_WORLD);
  MPI_Bcast(sum.data(), static_cast<int>(sum.size()), MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  return sum;
}

// A block held as a plain column-major array, wrapped as a PETSc dense matrix over the same
// storage: a block product reads A once for several columns, and the V-cycle smooths the
// columns together.
Mat dense(const double* a, Eigen::Index rows, Eigen::Index ncols) {
  Mat d;
  HEXFEM_PETSC(MatCreateDense(PETSC_COMM_WORLD, rows, PETSC_DECIDE, PETSC_DETERMINE, ncols,
                              const_cast<double*>(a), &d));
  return d;
}

// out = A in.
void multiply(Mat A, const MatrixXd& in, MatrixXd& out) {
  out.resize(in.rows(), in.cols());
  if (in.cols() == 0) return;
  Mat b = dense(in.data(), in.rows(), in.cols()), c = dense(out.data(), out.rows(), out.cols());
  HEXFEM_PETSC(MatProductCreateWithMat(A, b, nullptr, c));
  HEXFEM_PETSC(MatProductSetType(c, MATPRODUCT_AB));
  HEXFEM_PETSC(MatProductSetFromOptions(c));
  HEXFEM_PETSC(MatProductSymbolic(c));
  HEXFEM_PETSC(MatProductNumeric(c));
  MatDestroy(&b);
  MatDestroy(&c);
}

// out = T in, T an operator on dense blocks (the preconditioner, or A's own product).
void apply(const std::function<void(Mat, Mat)>& T, const Eigen::Ref<const MatrixXd>& in,
           MatrixXd& out) {
  out.resize(in.rows(), in.cols());
  if (in.cols() == 0) return;
  Mat b = dense(in.data(), in.rows(), in.cols()), c = dense(out.data(), out.rows(), out.cols());
  T(b, c);
  MatDestroy(&b);
  MatDestroy(&c);
}

// Directions whose Gram eigenvalue is below this fraction of the largest are round-off.
constexpr double kDropFraction = 1e-13;

// For a Gram matrix G = Sᵀ B S: T with Tᵀ G T = I on the directions of S above round-off
// (diagonally scaled eigendecomposition, SVQB); its columns span fewer than S's when S is
// (nearly) dependent.
MatrixXd orthonormalizing_transform(const MatrixXd& G) {
  const VectorXd d = G.diagonal().cwiseMax(0).cwiseSqrt();
  VectorXd dinv(d.size());
  for (Eigen::Index i = 0; i < d.size(); ++i) dinv[i] = d[i] > 0 ? 1 / d[i] : 0;
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(dinv.asDiagonal() * G * dinv.asDiagonal());
  const VectorXd& theta = es.eigenvalues();  // ascending
  const double top = theta.size() ? theta[theta.size() - 1] : 0;
  Eigen::Index first = 0;
  while (first < theta.size() && !(theta[first] > kDropFraction * top)) ++first;
  const Eigen::Index kept = theta.size() - first;
  MatrixXd T = dinv.asDiagonal() * es.eigenvectors().rightCols(kept);
  for (Eigen::Index j = 0; j < kept; ++j) T.col(j) /= std::sqrt(theta[first + j]);
  return T;
}

// U = U T, through the scratch block tmp.
void transform(MatrixXd& U, const MatrixXd& T, MatrixXd& tmp) {
  combine(U, T, 0, tmp);
  U.swap(tmp);
}

// B-orthonormalizes the columns of U, dropping dependent directions; BU (and AU when given)
// follow without new products, through the scratch block tmp. Returns the columns kept.
long orthonormalize(MatrixXd& U, MatrixXd& BU, MatrixXd* AU, MatrixXd& tmp) {
  if (U.cols() == 0) return 0;
  const MatrixXd T = orthonormalizing_transform(inner(U, BU));
  transform(U, T, tmp);
  transform(BU, T, tmp);
  if (AU) transform(*AU, T, tmp);
  return T.cols();
}

// U -= V (BVᵀ U): B-orthogonal to the B-orthonormal V.
void project_out(const MatrixXd& V, const MatrixXd& BV, MatrixXd& U) {
  if (V.cols() == 0 || U.cols() == 0) return;
  combine(V, -inner(BV, U), 1, U);
}

// The Rayleigh-Ritz step on the basis [blocks...]: the m lowest Ritz values and, per block, the
// rows of the coefficient matrix. Returns false when the basis holds fewer than m directions.
struct Basis {
  std::vector<const MatrixXd*> S, AS, BS;
};
bool rayleigh_ritz(const Basis& b, long m, VectorXd& theta, std::vector<MatrixXd>& coef) {
  std::vector<long> off{0};
  for (const MatrixXd* s : b.S) off.push_back(off.back() + s->cols());
  const long k = off.back();
  MatrixXd Ga(k, k), Gb(k, k);
  for (std::size_t i = 0; i < b.S.size(); ++i)
    for (std::size_t j = i; j < b.S.size(); ++j) {
      const MatrixXd a = inner(*b.S[i], *b.AS[j]), bb = inner(*b.S[i], *b.BS[j]);
      Ga.block(off[i], off[j], a.rows(), a.cols()) = a;
      Ga.block(off[j], off[i], a.cols(), a.rows()) = a.transpose();
      Gb.block(off[i], off[j], bb.rows(), bb.cols()) = bb;
      Gb.block(off[j], off[i], bb.cols(), bb.rows()) = bb.transpose();
    }
  // The basis B-orthonormalized, without its null part.
  const MatrixXd T = orthonormalizing_transform(Gb);
  if (T.cols() < m) return false;
  MatrixXd Ha = T.transpose() * Ga * T;
  const Eigen::SelfAdjointEigenSolver<MatrixXd> ea(0.5 * (Ha + Ha.transpose()));
  theta = ea.eigenvalues().head(m);
  const MatrixXd C = T * ea.eigenvectors().leftCols(m);
  coef.clear();
  for (std::size_t i = 0; i < b.S.size(); ++i)
    coef.push_back(C.middleRows(off[i], off[i + 1] - off[i]));
  return true;
}

double unit_random(std::uint64_t key) {  // splitmix64: the same start for any number of ranks
  key += 0x9e3779b97f4a7c15ULL;
  key = (key ^ (key >> 30)) * 0xbf58476d1ce4e5b9ULL;
  key = (key ^ (key >> 27)) * 0x94d049bb133111ebULL;
  key ^= key >> 31;
  return static_cast<double>(key >> 11) * 0x1.0p-52 - 1.0;  // [-1, 1)
}

}  // namespace

LobpcgResult lobpcg(const LobpcgProblem& p, const LobpcgOptions& o) {
  LobpcgResult res;
  const long m = std::max(o.nev, o.block);
  PetscInt nloc, lo, hi;
  HEXFEM_PETSC(MatGetLocalSize(p.A, &nloc, nullptr));
  HEXFEM_PETSC(MatGetOwnershipRange(p.A, &lo, &hi));

  // The constraints Y and BY.
  MatrixXd Y(nloc, p.constraints.size()), BY;
  for (std::size_t j = 0; j < p.constraints.size(); ++j) {
    const PetscScalar* a;
    HEXFEM_PETSC(VecGetArrayRead(p.constraints[j], &a));
    std::copy_n(a, nloc, Y.col(j).data());
    HEXFEM_PETSC(VecRestoreArrayRead(p.constraints[j], &a));
  }
  multiply(p.B, Y, BY);

  // Start: a random block, B-orthogonal to Y, B-orthonormal, then its Ritz vectors.
  // R: the residuals, and the scratch block wherever they are dead (10 blocks in all).
  MatrixXd X(nloc, m), AX, BX, W, AW, BW, P, AP, BP, R;
  for (long j = 0; j < m; ++j)
    for (PetscInt i = 0; i < nloc; ++i)
      X(i, j) =
          unit_random(static_cast<std::uint64_t>(lo + i) * 1024 + static_cast<std::uint64_t>(j));
  project_out(Y, BY, X);
  multiply(p.B, X, BX);
  if (orthonormalize(X, BX, nullptr, R) < m) {
    res.failure = "broke down: the start block is rank deficient";
    return res;
  }
  const auto multiply_a = [&](const MatrixXd& in, MatrixXd& out) {
    if (p.multiply_a)
      apply(p.multiply_a, in, out);
    else
      multiply(p.A, in, out);
  };
  multiply_a(X, AX);
  VectorXd lambda;
  std::vector<MatrixXd> c;
  if (!rayleigh_ritz({{&X}, {&AX}, {&BX}}, m, lambda, c)) {
    res.failure = "broke down: the start block is rank deficient";
    return res;
  }
  transform(X, c[0], R);
  transform(AX, c[0], R);
  transform(BX, c[0], R);

  const double scale = std::sqrt(o.mass_per_dof);
  bool fresh = true;  // AX and BX are exact products (not updated by combinations)
  std::vector<long> active;
  // res.worst of each iteration from the second: the start block's own error can lie far below
  // the next ones' (nist_ctc at order 2: a window from it made a converging run look stalled).
  std::vector<double> history;
  for (int it = 1;; ++it) {
    // Residuals and the convergence test.
    R = AX - BX * lambda.asDiagonal();
    VectorXd local = R.colwise().squaredNorm().transpose(), norm2(m);
    MPI_Allreduce(local.data(), norm2.data(), static_cast<int>(m), MPI_DOUBLE, MPI_SUM,
                  PETSC_COMM_WORLD);
    MPI_Bcast(norm2.data(), static_cast<int>(m), MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    active.clear();
    res.converged = 0;
    res.worst = 0;
    for (long j = 0; j < m; ++j) {
      const double err = std::sqrt(norm2[j]) / (std::max(std::abs(lambda[j]), o.floor) * scale);
      const bool ok = err < o.tolerance;
      if (j < o.nev) {
        res.worst = std::max(res.worst, err);
        res.converged += ok;
      }
      if (j >= o.nev || !ok) active.push_back(j);
    }
    res.iterations = it - 1;
    if (o.monitor && it > 1) o.monitor(res.iterations, res.converged, res.worst);
    if (res.converged == o.nev) {
      if (fresh) break;
      // The updated products drift by round-off: test once more on exact ones.
      multiply_a(X, AX);
      multiply(p.B, X, BX);
      fresh = true;
      --it;
      continue;
    }
    if (it > 1) history.push_back(res.worst);
    // The iteration by which the rate of the last window, kept up, meets the tolerance: NaN
    // before a whole window, infinity when the window fell by less than 10 %.
    const auto w = static_cast<std::size_t>(o.progress_window);
    double end = std::numeric_limits<double>::quiet_NaN();
    if (w > 0 && history.size() > w) {
      end = std::numeric_limits<double>::infinity();
      const double ratio = res.worst / history[history.size() - 1 - w];
      if (res.worst <= 0)
        end = it;
      else if (ratio < 0.9)
        end = it + std::log(res.worst / o.tolerance) / -std::log(ratio) * w;
    }
    // Past max_iterations, go on while that meets the budget (NaN compares false: stop).
    if (it > o.max_iterations && !(end <= o.max_iterations_progressing)) {
      res.failure = "did not converge";
      break;
    }
    // --solver auto's hand-over: nothing converged and a rate that would need more than twice
    // stall_iterations (1385_Laufrad at order 2, 340k DOF: 340 iterations, foreseen at the 21st:
    // 33.7 s in all instead of 44.4 s waiting for the 60th; solver.md §18), or nothing converged
    // by stall_iterations with no such rate known. A run foreseen to end by twice the limit goes
    // on past it (Block at order 2, 540k DOF: 94 iterations, 80 s and 1.6 GB in all, where the
    // hand-over at the 60th took 204 s and 7.3 GB; solver.md §20).
    if (o.stall_iterations > 0 && res.converged == 0 &&
        (end > 2.0 * o.stall_iterations || (it > o.stall_iterations && std::isnan(end)))) {
      res.failure = "stalled";
      break;
    }
    // New directions: the preconditioned residuals of the active pairs, B-orthogonal to Y and X.
    for (std::size_t j = 0; j < active.size(); ++j)  // the active residuals to the front of R
      if (static_cast<long>(j) != active[j]) R.col(j) = R.col(active[j]);
    apply(p.precondition, R.leftCols(static_cast<long>(active.size())), W);
    project_out(Y, BY, W);
    project_out(X, BX, W);
    multiply(p.B, W, BW);
    orthonormalize(W, BW, nullptr, R);  // R is dead from here to the next residuals
    if (W.cols() == 0) {
      res.failure = "broke down: the preconditioned residuals lie in the iterate";
      break;
    }
    multiply_a(W, AW);
    if (P.cols() > 0) orthonormalize(P, BP, &AP, R);

    if (!rayleigh_ritz({{&X, &W, &P}, {&AX, &AW, &AP}, {&BX, &BW, &BP}}, m, lambda, c)) {
      res.failure = "broke down: the basis lost rank";
      break;
    }
    // D = W Cw + P Cp into R; the new P = D's active columns (in P's storage: the old P is
    // dead once D is made); the new X = X Cx + D, in R, swapped into X. No block is allocated
    // per iteration while the active count stays.
    const long na = static_cast<long>(active.size());
    const auto next = [&](MatrixXd& U, const MatrixXd& WU, MatrixXd& PU) {
      combine(WU, c[1], 0, R);
      combine(PU, c[2], 1, R);
      PU.resize(nloc, na);
      for (long j = 0; j < na; ++j) PU.col(j) = R.col(active[j]);
      combine(U, c[0], 1, R);
      U.swap(R);
    };
    next(X, W, P);
    next(AX, AW, AP);
    next(BX, BW, BP);
    fresh = false;
  }
  res.values = lambda.head(o.nev);
  res.vectors = X.leftCols(o.nev);
  return res;
}

}  // namespace hexfem
