#include "fem/row_block_product.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <utility>

#include "fem/petsc_env.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

// The kernels are compiled twice, for x86-64-v3 (AVX2, FMA: 22 % faster here) and for any x86-64,
// and the loader picks the one the CPU runs.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define HEXFEM_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define HEXFEM_CLONES
#endif

// Columns [c0, c0 + C) of y = beta y + alpha A x, rows of k values. C fixed so that the
// accumulators stay in registers.
template <int C>
HEXFEM_CLONES void rows_times_block(const CsrArrays& A, const double* x, int k, int c0, double* y,
                                    double alpha, double beta) {
#pragma omp parallel for schedule(static)
  for (PetscInt i = 0; i < A.n; ++i) {
    double acc[C] = {};
    for (PetscInt p = A.ia[i]; p < A.ia[i + 1]; ++p) {
      const double v = A.a[p];
      const double* xr = x + static_cast<long>(A.ja[p]) * k + c0;
      for (int c = 0; c < C; ++c) acc[c] += v * xr[c];
    }
    double* yr = y + static_cast<long>(i) * k + c0;
    if (beta == 0)
      for (int c = 0; c < C; ++c) yr[c] = alpha * acc[c];
    else
      for (int c = 0; c < C; ++c) yr[c] = beta * yr[c] + alpha * acc[c];
  }
}

using Kernel = void (*)(const CsrArrays&, const double*, int, int, double*, double, double);

template <int... C>
constexpr auto kernel_table(std::integer_sequence<int, C...>) {
  return std::array<Kernel, sizeof...(C)>{&rows_times_block<C + 1>...};
}
constexpr int kWidest = 16;  // wider blocks go through in chunks of 16 columns
constexpr auto kKernels = kernel_table(std::make_integer_sequence<int, kWidest>{});

void csr_times_block(const CsrArrays& A, const double* x, int k, double* y, double alpha,
                     double beta) {
  for (int c0 = 0; c0 < k; c0 += kWidest) {
    const int width = std::min(kWidest, k - c0);
    kKernels[width - 1](A, x, k, c0, y, alpha, beta);
  }
}

// y += Aᵀ x over A's rows [begin, end), rows of k values.
HEXFEM_CLONES void csr_transpose_times_block(const CsrArrays& A, PetscInt begin, PetscInt end,
                                             const double* x, int k, double* y) {
  for (PetscInt i = begin; i < end; ++i) {
    const double* xr = x + static_cast<long>(i) * k;
    for (PetscInt p = A.ia[i]; p < A.ia[i + 1]; ++p) {
      const double v = A.a[p];
      double* yr = y + static_cast<long>(A.ja[p]) * k;
      for (int c = 0; c < k; ++c) yr[c] += v * xr[c];
    }
  }
}

}  // namespace

RowBlockProduct::RowBlockProduct(Mat A, int k) : k_(k) {
  PetscBool mpi = PETSC_FALSE, seq = PETSC_FALSE;
  HEXFEM_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATMPIAIJ, &mpi));
  HEXFEM_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(A), MATSEQAIJ, &seq));
  if (!mpi && !seq) throw Error("RowBlockProduct: the matrix is not AIJ");
  HEXFEM_PETSC(MatGetLocalSize(A, &rows_, &cols_));
  const PetscInt* garray = nullptr;
  if (mpi)
    HEXFEM_PETSC(MatMPIAIJGetSeqAIJ(A, &diag_, &off_, &garray));
  else
    diag_ = A;
  HEXFEM_PETSC(PetscObjectReference(reinterpret_cast<PetscObject>(A)));
  whole_ = A;
  const auto open = [](Mat m, CsrArrays& c) {
    PetscBool done;
    HEXFEM_PETSC(MatGetRowIJ(m, 0, PETSC_FALSE, PETSC_FALSE, &c.n, &c.ia, &c.ja, &done));
    if (!done) throw Error("RowBlockProduct: no CSR access to the matrix");
    HEXFEM_PETSC(MatSeqAIJGetArrayRead(m, &c.a));
  };
  open(diag_, d_);
  if (!off_) return;
  open(off_, o_);
  HEXFEM_PETSC(MatGetSize(off_, nullptr, &ghosts_));
  HEXFEM_PETSC(VecCreateMPIWithArray(PetscObjectComm(reinterpret_cast<PetscObject>(A)), k,
                                     static_cast<PetscInt>(cols_) * k, PETSC_DECIDE, nullptr,
                                     &owned_));
  HEXFEM_PETSC(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(ghosts_) * k, &ghost_));
  IS from;
  HEXFEM_PETSC(ISCreateBlock(PETSC_COMM_SELF, k, ghosts_, garray, PETSC_COPY_VALUES, &from));
  HEXFEM_PETSC(VecScatterCreate(owned_, from, ghost_, nullptr, &scatter_));
  ISDestroy(&from);
}

RowBlockProduct::~RowBlockProduct() {
  const auto close = [](Mat m, CsrArrays& c) {
    if (!m || !c.ia) return;
    PetscBool done;
    MatSeqAIJRestoreArrayRead(m, &c.a);
    MatRestoreRowIJ(m, 0, PETSC_FALSE, PETSC_FALSE, &c.n, &c.ia, &c.ja, &done);
  };
  close(diag_, d_);
  close(off_, o_);
  VecScatterDestroy(&scatter_);
  VecDestroy(&owned_);
  VecDestroy(&ghost_);
  MatDestroy(&whole_);
}

void RowBlockProduct::multiply(const double* x, double* y, double alpha, double beta) {
  if (off_) {  // the ghost rows of x travel while the local part is computed
    HEXFEM_PETSC(VecPlaceArray(owned_, x));
    HEXFEM_PETSC(VecScatterBegin(scatter_, owned_, ghost_, INSERT_VALUES, SCATTER_FORWARD));
  }
  csr_times_block(d_, x, k_, y, alpha, beta);
  if (!off_) return;
  HEXFEM_PETSC(VecScatterEnd(scatter_, owned_, ghost_, INSERT_VALUES, SCATTER_FORWARD));
  HEXFEM_PETSC(VecResetArray(owned_));
  const PetscScalar* g;
  HEXFEM_PETSC(VecGetArrayRead(ghost_, &g));
  csr_times_block(o_, g, k_, y, alpha, 1.0);
  HEXFEM_PETSC(VecRestoreArrayRead(ghost_, &g));
}

// Rows of A scatter into shared rows of y: each thread sums its share of A's rows into its own
// copy of y (the first thread into y), then the copies are added.
void RowBlockProduct::multiply_transpose(const double* x, double* y) {
  const long size = static_cast<long>(cols_) * k_;
  const CsrArrays& d = d_;
  const int threads = omp_get_max_threads();
  std::fill(y, y + size, 0.0);
  if (threads == 1) {
    csr_transpose_times_block(d, 0, d.n, x, k_, y);
  } else {
    partial_.resize(static_cast<std::size_t>(threads - 1) * size);
#pragma omp parallel num_threads(threads)
    {
      const int t = omp_get_thread_num(), nt = omp_get_num_threads();
      double* out = t == 0 ? y : partial_.data() + (t - 1) * size;
      if (t > 0) std::fill(out, out + size, 0.0);
      csr_transpose_times_block(d, d.n * t / nt, d.n * (t + 1) / nt, x, k_, out);
#pragma omp barrier
#pragma omp for schedule(static)
      for (long j = 0; j < size; ++j)
        for (int u = 1; u < nt; ++u) y[j] += partial_[(u - 1) * size + j];
    }
  }
  if (!off_) return;
  HEXFEM_PETSC(VecSet(ghost_, 0.0));
  PetscScalar* g;
  HEXFEM_PETSC(VecGetArray(ghost_, &g));
  csr_transpose_times_block(o_, 0, o_.n, x, k_, g);
  HEXFEM_PETSC(VecRestoreArray(ghost_, &g));
  HEXFEM_PETSC(VecPlaceArray(owned_, y));  // the ghosts' sums go home
  HEXFEM_PETSC(VecScatterBegin(scatter_, ghost_, owned_, ADD_VALUES, SCATTER_REVERSE));
  HEXFEM_PETSC(VecScatterEnd(scatter_, ghost_, owned_, ADD_VALUES, SCATTER_REVERSE));
  HEXFEM_PETSC(VecResetArray(owned_));
}

}  // namespace hexfem
