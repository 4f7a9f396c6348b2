#include "fem/block_vcycle.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

#include "fem/petsc_env.hpp"

namespace hexfem {
namespace {

// C = op(A) X into the existing dense C (type MATPRODUCT_AB or MATPRODUCT_AtB).
void product(Mat A, Mat X, Mat C, MatProductType type) {
  HEXFEM_PETSC(MatProductCreateWithMat(A, X, nullptr, C));
  HEXFEM_PETSC(MatProductSetType(C, type));
  HEXFEM_PETSC(MatProductSetFromOptions(C));
  HEXFEM_PETSC(MatProductSymbolic(C));
  HEXFEM_PETSC(MatProductNumeric(C));
  HEXFEM_PETSC(MatProductClear(C));
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
  for (Level& L : levels_) {
    MatDestroy(&L.A);
    MatDestroy(&L.P);
    VecDestroy(&L.inv_diag);
  }
  KSPDestroy(&coarse_);
}

void BlockVcycle::apply(Mat in, Mat out) {
  cycle(static_cast<int>(levels_.size()) - 1, in, out);
}

// Chebyshev iteration of the first kind on D⁻¹A x = D⁻¹b over [emin, emax] (Saad, Iterative
// Methods, Alg. 12.1), every column at once.
void BlockVcycle::smooth(const Level& L, Mat b, Mat x, bool zero_guess) {
  PetscInt ncols;
  HEXFEM_PETSC(MatGetSize(b, nullptr, &ncols));
  const double theta = 0.5 * (L.emax + L.emin), delta = 0.5 * (L.emax - L.emin);
  const double sigma = theta / delta;
  Mat r, d, t;
  HEXFEM_PETSC(MatDuplicate(b, MAT_COPY_VALUES, &r));
  if (!zero_guess) {  // r = b - A x
    t = dense_like(L.A, ncols);
    product(L.A, x, t, MATPRODUCT_AB);
    HEXFEM_PETSC(MatAXPY(r, -1.0, t, SAME_NONZERO_PATTERN));
  } else {
    HEXFEM_PETSC(MatDuplicate(b, MAT_DO_NOT_COPY_VALUES, &t));
  }
  HEXFEM_PETSC(MatDuplicate(r, MAT_COPY_VALUES, &d));
  HEXFEM_PETSC(MatDiagonalScale(d, L.inv_diag, nullptr));
  HEXFEM_PETSC(MatScale(d, 1.0 / theta));
  double rho = 1.0 / sigma;
  for (int i = 1; i <= steps_; ++i) {
    if (i == 1 && zero_guess)
      HEXFEM_PETSC(MatCopy(d, x, SAME_NONZERO_PATTERN));
    else
      HEXFEM_PETSC(MatAXPY(x, 1.0, d, SAME_NONZERO_PATTERN));
    if (i == steps_) break;
    product(L.A, d, t, MATPRODUCT_AB);  // r -= A d
    HEXFEM_PETSC(MatAXPY(r, -1.0, t, SAME_NONZERO_PATTERN));
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    HEXFEM_PETSC(MatCopy(r, t, SAME_NONZERO_PATTERN));  // d = ρ'ρ d + 2ρ'/δ D⁻¹ r
    HEXFEM_PETSC(MatDiagonalScale(t, L.inv_diag, nullptr));
    HEXFEM_PETSC(MatScale(d, rho_next * rho));
    HEXFEM_PETSC(MatAXPY(d, 2.0 * rho_next / delta, t, SAME_NONZERO_PATTERN));
    rho = rho_next;
  }
  for (Mat* m : {&r, &d, &t}) MatDestroy(m);
}

void BlockVcycle::cycle(int l, Mat b, Mat x) {
  if (l == 0) {
    HEXFEM_PETSC(KSPMatSolve(coarse_, b, x));
    return;
  }
  const Level& L = levels_[l];
  const Level& C = levels_[l - 1];
  PetscInt ncols;
  HEXFEM_PETSC(MatGetSize(b, nullptr, &ncols));
  smooth(L, b, x, true);
  Mat r = dense_like(L.A, ncols), bc = dense_like(C.A, ncols), xc = dense_like(C.A, ncols);
  product(L.A, x, r, MATPRODUCT_AB);  // r = b - A x
  HEXFEM_PETSC(MatAYPX(r, -1.0, b, SAME_NONZERO_PATTERN));
  product(L.P, r, bc, MATPRODUCT_AtB);
  cycle(l - 1, bc, xc);
  product(L.P, xc, r, MATPRODUCT_AB);
  HEXFEM_PETSC(MatAXPY(x, 1.0, r, SAME_NONZERO_PATTERN));
  smooth(L, b, x, false);
  for (Mat* m : {&r, &bc, &xc}) MatDestroy(m);
}

}  // namespace hexfem
