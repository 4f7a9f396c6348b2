#include "fem/block_vcycle.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

#include "fem/petsc_env.hpp"

namespace hexfem {
namespace {

// Attaches C = op(A) X to the dense C; MatProductNumeric(C) then recomputes it from X's values.
void attach_product(Mat A, Mat X, Mat C, MatProductType type) {
  HEXFEM_PETSC(MatProductCreateWithMat(A, X, nullptr, C));
  HEXFEM_PETSC(MatProductSetType(C, type));
  HEXFEM_PETSC(MatProductSetFromOptions(C));
  HEXFEM_PETSC(MatProductSymbolic(C));
}

Mat dense_like(Mat A, PetscInt ncols) {  // rows laid out as A's rows
  PetscInt nloc, N;
  HEXFEM_PETSC(MatGetLocalSize(A, &nloc, nullptr));
  HEXFEM_PETSC(MatGetSize(A, &N, nullptr));
  Mat d;
  HEXFEM_PETSC(MatCreateDense(PETSC_COMM_WORLD, nloc, PETSC_DECIDE, N, ncols, nullptr, &d));
  return d;
}

// The largest eigenvalue of D⁻¹A by 12 Lanczos steps on D^-1/2 A D^-1/2 (a lower bound within a
// few per cent; the Chebyshev interval's upper end adds 10 %).
double largest_eigenvalue(Mat A, Vec inv_diag) {
  constexpr int kSteps = 12;
  Vec s, v, v_prev, w, u;
  HEXFEM_PETSC(VecDuplicate(inv_diag, &s));
  HEXFEM_PETSC(VecCopy(inv_diag, s));
  HEXFEM_PETSC(VecSqrtAbs(s));
  HEXFEM_PETSC(VecDuplicate(s, &v));
  HEXFEM_PETSC(VecDuplicate(s, &v_prev));
  HEXFEM_PETSC(VecDuplicate(s, &w));
  HEXFEM_PETSC(VecDuplicate(s, &u));
  PetscInt lo, hi;
  HEXFEM_PETSC(VecGetOwnershipRange(v, &lo, &hi));
  PetscScalar* a;
  HEXFEM_PETSC(VecGetArray(v, &a));
  for (PetscInt i = lo; i < hi; ++i) {  // the same start for any number of ranks
    std::uint64_t k = static_cast<std::uint64_t>(i) * 0x9e3779b97f4a7c15ULL;
    k ^= k >> 29;
    a[i - lo] = 0.5 + static_cast<double>(k % 1000) / 1000.0;
  }
  HEXFEM_PETSC(VecRestoreArray(v, &a));
  PetscReal norm;
  HEXFEM_PETSC(VecNormalize(v, &norm));
  HEXFEM_PETSC(VecSet(v_prev, 0.0));
  std::vector<double> alpha, beta;
  double b = 0;
  for (int j = 0; j < kSteps; ++j) {
    HEXFEM_PETSC(VecPointwiseMult(u, s, v));  // w = S A S v
    HEXFEM_PETSC(MatMult(A, u, w));
    HEXFEM_PETSC(VecPointwiseMult(w, s, w));
    PetscScalar al;
    HEXFEM_PETSC(VecDot(w, v, &al));
    alpha.push_back(al);
    HEXFEM_PETSC(VecAXPY(w, -al, v));
    HEXFEM_PETSC(VecAXPY(w, -b, v_prev));
    HEXFEM_PETSC(VecNorm(w, NORM_2, &norm));
    if (!(norm > 1e-14 * std::abs(al))) break;
    b = norm;
    beta.push_back(b);
    HEXFEM_PETSC(VecCopy(v, v_prev));
    HEXFEM_PETSC(VecCopy(w, v));
    HEXFEM_PETSC(VecScale(v, 1.0 / b));
  }
  const int k = static_cast<int>(alpha.size());
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k, k);
  for (int i = 0; i < k; ++i) {
    T(i, i) = alpha[i];
    if (i + 1 < k) T(i, i + 1) = T(i + 1, i) = beta[i];
  }
  for (Vec* x : {&s, &v, &v_prev, &w, &u}) VecDestroy(x);
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

}  // namespace

BlockVcycle::BlockVcycle(PC pc, int chebyshev_steps, double lo, double hi)
    : steps_(chebyshev_steps) {
  PetscInt n;
  HEXFEM_PETSC(PCMGGetLevels(pc, &n));
  levels_.resize(n);
  for (PetscInt l = 0; l < n; ++l) {
    Level& L = levels_[l];
    KSP smoother;
    HEXFEM_PETSC(PCMGGetSmoother(pc, l, &smoother));
    HEXFEM_PETSC(KSPGetOperators(smoother, &L.A, nullptr));
    HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(L.A)));
    if (l > 0) {
      HEXFEM_PETSC(PCMGGetInterpolation(pc, l, &L.P));
      HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(L.P)));
      HEXFEM_PETSC(MatCreateVecs(L.A, &L.inv_diag, nullptr));
      HEXFEM_PETSC(MatGetDiagonal(L.A, L.inv_diag));
      HEXFEM_PETSC(VecReciprocal(L.inv_diag));
      const double top = largest_eigenvalue(L.A, L.inv_diag);
      L.emin = lo * top;
      L.emax = hi * top;
    }
  }
  HEXFEM_PETSC(PCMGGetCoarseSolve(pc, &coarse_));
  HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(coarse_)));
}

BlockVcycle::~BlockVcycle() {
  release();
  for (Level& L : levels_) {
    MatDestroy(&L.A);
    MatDestroy(&L.P);
    VecDestroy(&L.inv_diag);
  }
  KSPDestroy(&coarse_);
}

void BlockVcycle::release() {
  for (Level& L : levels_)
    for (Mat* m : {&L.b, &L.x, &L.r, &L.d, &L.ad, &L.ax, &L.e}) MatDestroy(m);
  ncols_ = 0;
}

void BlockVcycle::prepare(PetscInt ncols) {
  if (ncols == ncols_) return;
  release();
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = levels_[l];
    L.b = dense_like(L.A, ncols);
    L.x = dense_like(L.A, ncols);
    if (l == 0) continue;
    for (Mat* m : {&L.r, &L.d, &L.ad, &L.ax, &L.e}) *m = dense_like(L.A, ncols);
  }
  for (std::size_t l = 1; l < levels_.size(); ++l) {
    Level &L = levels_[l], &C = levels_[l - 1];
    attach_product(L.A, L.d, L.ad, MATPRODUCT_AB);
    attach_product(L.A, L.x, L.ax, MATPRODUCT_AB);
    attach_product(L.P, C.x, L.e, MATPRODUCT_AB);
    attach_product(L.P, L.r, C.b, MATPRODUCT_AtB);
  }
  ncols_ = ncols;
}

void BlockVcycle::apply(Mat in, Mat out) {
  PetscInt ncols;
  HEXFEM_PETSC(MatGetSize(in, nullptr, &ncols));
  prepare(ncols);
  Level& top = levels_.back();
  HEXFEM_PETSC(MatCopy(in, top.b, SAME_NONZERO_PATTERN));
  cycle(static_cast<int>(levels_.size()) - 1);
  HEXFEM_PETSC(MatCopy(top.x, out, SAME_NONZERO_PATTERN));
}

// Chebyshev iteration of the first kind on D⁻¹A x = D⁻¹b over [emin, emax] (Saad, Iterative
// Methods, Alg. 12.1), every column at once; x = 0 on entry when zero_guess.
void BlockVcycle::smooth(Level& L, bool zero_guess) {
  const double theta = 0.5 * (L.emax + L.emin), delta = 0.5 * (L.emax - L.emin);
  const double sigma = theta / delta;
  HEXFEM_PETSC(MatCopy(L.b, L.r, SAME_NONZERO_PATTERN));
  if (!zero_guess) {  // r = b - A x
    HEXFEM_PETSC(MatProductNumeric(L.ax));
    HEXFEM_PETSC(MatAXPY(L.r, -1.0, L.ax, SAME_NONZERO_PATTERN));
  }
  HEXFEM_PETSC(MatCopy(L.r, L.d, SAME_NONZERO_PATTERN));
  HEXFEM_PETSC(MatDiagonalScale(L.d, L.inv_diag, nullptr));
  HEXFEM_PETSC(MatScale(L.d, 1.0 / theta));
  double rho = 1.0 / sigma;
  for (int i = 1; i <= steps_; ++i) {
    if (i == 1 && zero_guess)
      HEXFEM_PETSC(MatCopy(L.d, L.x, SAME_NONZERO_PATTERN));
    else
      HEXFEM_PETSC(MatAXPY(L.x, 1.0, L.d, SAME_NONZERO_PATTERN));
    if (i == steps_) break;
    HEXFEM_PETSC(MatProductNumeric(L.ad));  // r -= A d
    HEXFEM_PETSC(MatAXPY(L.r, -1.0, L.ad, SAME_NONZERO_PATTERN));
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    // d = ρ'ρ d + 2ρ'/δ D⁻¹ r, with ad (consumed above) as the scratch block for D⁻¹ r.
    HEXFEM_PETSC(MatCopy(L.r, L.ad, SAME_NONZERO_PATTERN));
    HEXFEM_PETSC(MatDiagonalScale(L.ad, L.inv_diag, nullptr));
    HEXFEM_PETSC(MatScale(L.d, rho_next * rho));
    HEXFEM_PETSC(MatAXPY(L.d, 2.0 * rho_next / delta, L.ad, SAME_NONZERO_PATTERN));
    rho = rho_next;
  }
}

// One V-cycle on level l from its b into its x.
void BlockVcycle::cycle(int l) {
  Level& L = levels_[l];
  if (l == 0) {
    HEXFEM_PETSC(KSPMatSolve(coarse_, L.b, L.x));
    return;
  }
  Level& C = levels_[l - 1];
  smooth(L, true);
  HEXFEM_PETSC(MatProductNumeric(L.ax));  // r = b - A x
  HEXFEM_PETSC(MatCopy(L.b, L.r, SAME_NONZERO_PATTERN));
  HEXFEM_PETSC(MatAXPY(L.r, -1.0, L.ax, SAME_NONZERO_PATTERN));
  HEXFEM_PETSC(MatProductNumeric(C.b));  // b_c = Pᵀ r
  cycle(l - 1);
  HEXFEM_PETSC(MatProductNumeric(L.e));  // x += P x_c
  HEXFEM_PETSC(MatAXPY(L.x, 1.0, L.e, SAME_NONZERO_PATTERN));
  smooth(L, false);
}

}  // namespace hexfem
