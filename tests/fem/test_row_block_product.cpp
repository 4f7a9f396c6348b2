// The row-block kernel of the iterative path (fem/row_block_product.hpp) against a dense product
// computed here from the same entries: y = beta y + alpha A x and y = Aᵀ x, for block widths on
// both sides of the kernels' fixed widths (1..16, wider ones in chunks).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "fem/petsc_env.hpp"
#include "fem/row_block_product.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

struct Sparse {
  Mat A = nullptr;
  Eigen::MatrixXd dense;  // the same entries
};

// A rows x cols matrix with about 8 entries per row at pseudo-random places.
Sparse random_sparse(PetscInt rows, PetscInt cols) {
  Sparse s;
  s.dense = Eigen::MatrixXd::Zero(rows, cols);
  std::uint64_t state = 12345;
  const auto next = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return state >> 33;
  };
  HEXFEM_PETSC(MatCreateSeqAIJ(PETSC_COMM_SELF, rows, cols, 8, nullptr, &s.A));
  for (PetscInt i = 0; i < rows; ++i)
    for (int e = 0; e < 8; ++e) {
      const PetscInt j = static_cast<PetscInt>(next() % cols);
      const double v = static_cast<double>(next() % 2001) / 1000.0 - 1.0;
      HEXFEM_PETSC(MatSetValue(s.A, i, j, v, ADD_VALUES));
      s.dense(i, j) += v;
    }
  HEXFEM_PETSC(MatAssemblyBegin(s.A, MAT_FINAL_ASSEMBLY));
  HEXFEM_PETSC(MatAssemblyEnd(s.A, MAT_FINAL_ASSEMBLY));
  return s;
}

// Row-major storage of a dense block.
std::vector<double> rows_of(const Eigen::MatrixXd& m) {
  std::vector<double> r(m.size());
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) r[i * m.cols() + j] = m(i, j);
  return r;
}

double max_difference(const std::vector<double>& rows, const Eigen::MatrixXd& m) {
  double worst = 0;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      worst = std::max(worst, std::abs(rows[i * m.cols() + j] - m(i, j)));
  return worst;
}

TEST(RowBlockProduct, MatchesADenseProductForAnyBlockWidth) {
  ensure_petsc();
  Sparse s = random_sparse(301, 187);
  for (int k : {1, 3, 12, 16, 17, 40}) {
    RowBlockProduct p(s.A, k);
    EXPECT_EQ(p.rows(), 301);
    EXPECT_EQ(p.cols(), 187);
    const Eigen::MatrixXd x = Eigen::MatrixXd::Random(187, k), y0 = Eigen::MatrixXd::Random(301, k);
    std::vector<double> y = rows_of(y0);
    p.multiply(rows_of(x).data(), y.data(), -1.5, 1.0);
    EXPECT_LT(max_difference(y, y0 - 1.5 * s.dense * x), 1e-12) << "k = " << k;
    p.multiply(rows_of(x).data(), y.data(), 2.0, 0.0);  // beta = 0 ignores y
    EXPECT_LT(max_difference(y, 2.0 * s.dense * x), 1e-12) << "k = " << k;

    const Eigen::MatrixXd r = Eigen::MatrixXd::Random(301, k);
    std::vector<double> z(187 * k, 7.0);  // overwritten
    p.multiply_transpose(rows_of(r).data(), z.data());
    EXPECT_LT(max_difference(z, s.dense.transpose() * r), 1e-12) << "k = " << k;
  }
  MatDestroy(&s.A);
}

TEST(RowBlockProduct, RefusesAMatrixThatIsNotAij) {
  ensure_petsc();
  Mat d;
  HEXFEM_PETSC(MatCreateSeqDense(PETSC_COMM_SELF, 4, 4, nullptr, &d));
  HEXFEM_PETSC(MatAssemblyBegin(d, MAT_FINAL_ASSEMBLY));
  HEXFEM_PETSC(MatAssemblyEnd(d, MAT_FINAL_ASSEMBLY));
  EXPECT_THROW(RowBlockProduct(d, 2), Error);
  MatDestroy(&d);
}

}  // namespace
}  // namespace hexfem
