// Products of a PETSc AIJ matrix (one rank or several) with a block of k vectors stored row by
// row: the k values of one row are contiguous, so one pass over A's nonzeros serves every column
// (y_i += a_ij x_j is a k-wide vector operation). Why not PETSc's MatMatMult with a dense block:
// PETSc 3.18 multiplies AIJ by a column-major dense block four columns at a time, reading A three
// times for 12 columns; this kernel is 2.4x faster on the 81-nonzeros-per-row stiffness matrix of
// the 1M-DOF cantilever (measured, validation/solver.md §10), and that product is most of an
// LOBPCG iteration. Rows are split over OpenMP threads on each rank; the values of the ghost rows
// (off-rank columns) travel by a PETSc VecScatter with block size k.
#pragma once

#include <petscmat.h>

#include <vector>

namespace hexfem {

// A sequential AIJ matrix's arrays (PETSc's own, read in place).
struct CsrArrays {
  PetscInt n = 0;  // rows
  const PetscInt *ia = nullptr, *ja = nullptr;
  const PetscScalar* a = nullptr;
};

class RowBlockProduct {
 public:
  // A: MATSEQAIJ or MATMPIAIJ, assembled and not changed while this object lives; k >= 1.
  RowBlockProduct(Mat A, int k);
  ~RowBlockProduct();
  RowBlockProduct(const RowBlockProduct&) = delete;
  RowBlockProduct& operator=(const RowBlockProduct&) = delete;

  // y = beta y + alpha A x. x: the rank's columns of A (cols() rows of k values); y: its rows.
  // beta = 0 ignores y's values.
  void multiply(const double* x, double* y, double alpha, double beta);
  // y = Aᵀ x. x: the rank's rows; y: its columns (overwritten).
  void multiply_transpose(const double* x, double* y);

  PetscInt rows() const { return rows_; }  // on this rank
  PetscInt cols() const { return cols_; }

 private:
  Mat whole_ = nullptr;                 // A (referenced)
  Mat diag_ = nullptr, off_ = nullptr;  // A's parts: this rank's columns, others' (MPI only)
  CsrArrays d_, o_;
  int k_;
  PetscInt rows_ = 0, cols_ = 0, ghosts_ = 0;
  Vec owned_ = nullptr, ghost_ = nullptr;  // wrappers over the caller's x (or y) and the ghosts
  VecScatter scatter_ = nullptr;
  std::vector<double> partial_;  // the other threads' sums in multiply_transpose
};

}  // namespace hexfem
