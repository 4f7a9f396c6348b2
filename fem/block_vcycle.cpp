#include "fem/block_vcycle.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

#include "fem/petsc_env.hpp"

namespace hexfem {
namespace {

Mat dense_like(Mat A, PetscInt ncols) {  // rows laid out as A's rows
  PetscInt nloc, N;
  HEXFEM_PETSC(MatGetLocalSize(A, &nloc, nullptr));
  HEXFEM_PETSC(MatGetSize(A, &N, nullptr));
  Mat d;
  HEXFEM_PETSC(MatCreateDense(PETSC_COMM_WORLD, nloc, PETSC_DECIDE, N, ncols, nullptr, &d));
  return d;
}

// rows (n rows of k values) <-> a PETSc dense block (column-major, n local rows, k columns).
void dense_to_rows(Mat m, std::vector<double>& rows, int k) {
  const PetscScalar* a;
  PetscInt lda, n;
  HEXFEM_PETSC(MatDenseGetLDA(m, &lda));
  HEXFEM_PETSC(MatGetLocalSize(m, &n, nullptr));
  HEXFEM_PETSC(MatDenseGetArrayRead(m, &a));
#pragma omp parallel for schedule(static)
  for (PetscInt i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j)
      rows[static_cast<long>(i) * k + j] = a[static_cast<long>(j) * lda + i];
  HEXFEM_PETSC(MatDenseRestoreArrayRead(m, &a));
}

void rows_to_dense(const std::vector<double>& rows, int k, Mat m) {
  PetscScalar* a;
  PetscInt lda, n;
  HEXFEM_PETSC(MatDenseGetLDA(m, &lda));
  HEXFEM_PETSC(MatGetLocalSize(m, &n, nullptr));
  HEXFEM_PETSC(MatDenseGetArrayWrite(m, &a));
#pragma omp parallel for schedule(static)
  for (PetscInt i = 0; i < n; ++i)
    for (int j = 0; j < k; ++j)
      a[static_cast<long>(j) * lda + i] = rows[static_cast<long>(i) * k + j];
  HEXFEM_PETSC(MatDenseRestoreArrayWrite(m, &a));
}

// An upper estimate of the largest eigenvalue of D⁻¹A: 12 Lanczos steps on D^-1/2 A D^-1/2 from
// a zero-mean start (a positive start is mostly smooth modes, whose Ritz values can stay far
// below the top), the largest Ritz value plus its residual norm |β_k s_k| (some eigenvalue lies
// within it; the Chebyshev interval's upper end adds 10 % more). An underestimate makes the
// Chebyshev smoother amplify the top modes, and the V-cycle indefinite.
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
    a[i - lo] = static_cast<double>(k % 1000) / 1000.0 - 0.5;
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
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(T);
  const double residual = static_cast<int>(beta.size()) == k
                              ? beta.back() * std::abs(es.eigenvectors()(k - 1, k - 1))
                              : 0.0;  // the Krylov space closed: the Ritz value is exact
  return es.eigenvalues()(k - 1) + residual;
}

}  // namespace

BlockVcycle::BlockVcycle(PC pc, int chebyshev_steps, double lo, double hi)
    : steps_(chebyshev_steps), lo_(lo), hi_(hi) {
  PetscInt n;
  HEXFEM_PETSC(PCMGGetLevels(pc, &n));
  levels_.resize(n);
  for (PetscInt l = 0; l < n; ++l) {
    Level& L = levels_[l];
    KSP smoother;
    HEXFEM_PETSC(PCMGGetSmoother(pc, l, &smoother));
    HEXFEM_PETSC(KSPGetOperators(smoother, &L.A, nullptr));
    HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(L.A)));
    if (l == 0) continue;
    HEXFEM_PETSC(PCMGGetInterpolation(pc, l, &L.P));
    HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(L.P)));
    set_up_smoother(L);
  }
  HEXFEM_PETSC(PCMGGetCoarseSolve(pc, &coarse_));
  HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(coarse_)));
}

void BlockVcycle::add_finer_level(Mat A, Mat P) {
  Level& L = levels_.emplace_back();
  L.A = A;
  L.P = P;
  HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(L.A)));
  HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(L.P)));
  set_up_smoother(L);
  k_ = 0;  // the work blocks are laid out for the old finest level
}

void BlockVcycle::set_up_smoother(Level& L) {
  Vec inv_diag;
  HEXFEM_PETSC(MatCreateVecs(L.A, &inv_diag, nullptr));
  HEXFEM_PETSC(MatGetDiagonal(L.A, inv_diag));
  HEXFEM_PETSC(VecReciprocal(inv_diag));
  const double top = largest_eigenvalue(L.A, inv_diag);
  L.emin = lo_ * top;
  L.emax = hi_ * top;
  PetscInt nloc;
  const PetscScalar* v;
  HEXFEM_PETSC(VecGetLocalSize(inv_diag, &nloc));
  HEXFEM_PETSC(VecGetArrayRead(inv_diag, &v));
  L.inv_diag.assign(v, v + nloc);
  HEXFEM_PETSC(VecRestoreArrayRead(inv_diag, &v));
  VecDestroy(&inv_diag);
}

BlockVcycle::~BlockVcycle() {
  for (Level& L : levels_) {  // the block products hold their own references
    MatDestroy(&L.A);
    MatDestroy(&L.P);
  }
  MatDestroy(&coarse_b_);
  MatDestroy(&coarse_x_);
  KSPDestroy(&coarse_);
}

void BlockVcycle::prepare(int k) {
  if (k == k_) return;
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = levels_[l];
    PetscInt n;
    HEXFEM_PETSC(MatGetLocalSize(L.A, &n, nullptr));
    const std::size_t size = static_cast<std::size_t>(n) * k;
    // The finest level of several reads its right-hand side from apply()'s input instead (one
    // block less on the largest level).
    if (l + 1 == levels_.size() && l > 0)
      std::vector<double>().swap(L.b);
    else
      L.b.assign(size, 0.0);
    L.x.assign(size, 0.0);
    if (l == 0) {
      if (levels_.size() == 1) L.a = std::make_unique<RowBlockProduct>(L.A, k);  // finest
      continue;
    }
    L.r.assign(size, 0.0);
    L.d.assign(size, 0.0);
    L.a = std::make_unique<RowBlockProduct>(L.A, k);
    L.p = std::make_unique<RowBlockProduct>(L.P, k);
  }
  MatDestroy(&coarse_b_);
  MatDestroy(&coarse_x_);
  coarse_b_ = dense_like(levels_[0].A, k);
  coarse_x_ = dense_like(levels_[0].A, k);
  k_ = k;
}

void BlockVcycle::apply(Mat in, Mat out) {
  PetscInt k;
  HEXFEM_PETSC(MatGetSize(in, nullptr, &k));
  prepare(static_cast<int>(k));
  Level& top = levels_.back();
  rhs_ = in;
  if (!top.b.empty()) dense_to_rows(in, top.b, k_);
  cycle(static_cast<int>(levels_.size()) - 1);
  rows_to_dense(top.x, k_, out);
  rhs_ = nullptr;
}

void BlockVcycle::apply(Vec in, Vec out) {
  PetscInt nloc, n;
  HEXFEM_PETSC(VecGetLocalSize(in, &nloc));
  HEXFEM_PETSC(VecGetSize(in, &n));
  const PetscScalar* a;
  PetscScalar* b;
  HEXFEM_PETSC(VecGetArrayRead(in, &a));  // a KSP locks its right-hand side for reading
  HEXFEM_PETSC(VecGetArray(out, &b));
  Mat x, y;  // one-column views of the two vectors; x is only read
  HEXFEM_PETSC(
      MatCreateDense(PETSC_COMM_WORLD, nloc, PETSC_DECIDE, n, 1, const_cast<PetscScalar*>(a), &x));
  HEXFEM_PETSC(MatCreateDense(PETSC_COMM_WORLD, nloc, PETSC_DECIDE, n, 1, b, &y));
  apply(x, y);
  MatDestroy(&x);
  MatDestroy(&y);
  HEXFEM_PETSC(VecRestoreArray(out, &b));
  HEXFEM_PETSC(VecRestoreArrayRead(in, &a));
}

void BlockVcycle::load_rhs(Level& L) {
  if (L.b.empty())
    dense_to_rows(rhs_, L.r, k_);
  else
    L.r = L.b;
}

void BlockVcycle::multiply_finest(Mat in, Mat out) {
  PetscInt k;
  HEXFEM_PETSC(MatGetSize(in, nullptr, &k));
  prepare(static_cast<int>(k));
  Level& top = levels_.back();
  std::vector<double>& rows = top.b.empty() ? top.r : top.b;  // idle outside apply()
  dense_to_rows(in, rows, k_);
  top.a->multiply(rows.data(), top.x.data(), 1.0, 0.0);
  rows_to_dense(top.x, k_, out);
}

// Chebyshev iteration of the first kind on D⁻¹A x = D⁻¹b over [emin, emax] (Saad, Iterative
// Methods, Alg. 12.1), every column at once; x = 0 on entry when zero_guess.
void BlockVcycle::smooth(Level& L, bool zero_guess) {
  const double theta = 0.5 * (L.emax + L.emin), delta = 0.5 * (L.emax - L.emin);
  const double sigma = theta / delta;
  const long n = static_cast<long>(L.inv_diag.size()), k = k_;
  double *r = L.r.data(), *d = L.d.data(), *x = L.x.data();
  const double* inv = L.inv_diag.data();
  load_rhs(L);
  if (!zero_guess) L.a->multiply(x, r, -1.0, 1.0);  // r = b - A x
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i)
    for (long c = 0; c < k; ++c) d[i * k + c] = inv[i] / theta * r[i * k + c];
  double rho = 1.0 / sigma;
  for (int step = 1; step <= steps_; ++step) {
    if (step == 1 && zero_guess)
      L.x = L.d;
    else
#pragma omp parallel for schedule(static)
      for (long j = 0; j < n * k; ++j) x[j] += d[j];
    if (step == steps_) break;
    L.a->multiply(d, r, -1.0, 1.0);  // r -= A d
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    const double keep = rho_next * rho, gain = 2.0 * rho_next / delta;  // d = ρ'ρ d + 2ρ'/δ D⁻¹r
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i)
      for (long c = 0; c < k; ++c)
        d[i * k + c] = keep * d[i * k + c] + gain * inv[i] * r[i * k + c];
    rho = rho_next;
  }
}

// One V-cycle on level l from its b into its x.
void BlockVcycle::cycle(int l) {
  Level& L = levels_[l];
  if (l == 0) {
    rows_to_dense(L.b, k_, coarse_b_);
    HEXFEM_PETSC(KSPMatSolve(coarse_, coarse_b_, coarse_x_));
    dense_to_rows(coarse_x_, L.x, k_);
    return;
  }
  Level& C = levels_[l - 1];
  smooth(L, true);
  load_rhs(L);  // r = b - A x
  L.a->multiply(L.x.data(), L.r.data(), -1.0, 1.0);
  L.p->multiply_transpose(L.r.data(), C.b.data());  // b_c = Pᵀ r
  cycle(l - 1);
  L.p->multiply(C.x.data(), L.x.data(), 1.0, 1.0);  // x += P x_c
  smooth(L, false);
}

}  // namespace hexfem
