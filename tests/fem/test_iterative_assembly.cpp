// The iterative path's PETSc matrices (fem/iterative_assembly.cpp, accumulated in a node-block
// CSR, fem/block_csr.cpp) against the direct path's assembly (fem/assembly.cpp), entry by entry.
#include <gtest/gtest.h>
#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "app/part_modal.hpp"
#include "fem/assembly.hpp"
#include "fem/boundary.hpp"
#include "fem/iterative_assembly.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

// A PETSc matrix on one process as a dense one over the direct path's equations (the free DOFs);
// `upper`: only the upper triangle is stored (SBAIJ), mirrored here. Entries of fixed DOFs must
// lie on the diagonal; their count goes to `fixed_diagonal`.
Eigen::MatrixXd to_equations(Mat A, const DofLayout& L, const DofMap& dofs, bool upper,
                             long& fixed_diagonal) {
  const long n = dofs.num_free;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  const auto equation = [&](PetscInt r) { return dofs.dof[3 * L.order[r / 3] + r % 3]; };
  fixed_diagonal = 0;
  if (upper) HEXFEM_PETSC(MatGetRowUpperTriangular(A));
  for (PetscInt r = 0; r < 3 * static_cast<PetscInt>(L.order.size()); ++r) {
    PetscInt nc = 0;
    const PetscInt* cols = nullptr;
    const PetscScalar* vals = nullptr;
    HEXFEM_PETSC(MatGetRow(A, r, &nc, &cols, &vals));
    for (PetscInt k = 0; k < nc; ++k) {
      const long i = equation(r), j = equation(cols[k]);
      if (i < 0 || j < 0) {
        if (vals[k] == 0) continue;
        EXPECT_EQ(r, cols[k]) << "a fixed DOF coupled off the diagonal";
        ++fixed_diagonal;
        continue;
      }
      D(i, j) = vals[k];
      if (upper) D(j, i) = vals[k];
    }
    HEXFEM_PETSC(MatRestoreRow(A, r, &nc, &cols, &vals));
  }
  if (upper) HEXFEM_PETSC(MatRestoreRowUpperTriangular(A));
  return D;
}

// Largest |A_ij - B_ij| / sqrt(|B_ii B_jj|).
double worst_difference(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  double worst = 0;
  for (long j = 0; j < B.cols(); ++j)
    for (long i = 0; i < B.rows(); ++i)
      worst = std::max(worst, std::abs(A(i, j) - B(i, j)) / std::sqrt(std::abs(B(i, i) * B(j, j))));
  return worst;
}

TEST(IterativeAssembly, BlockCsrMatchesTheDirectAssembly) {
  // Order 2, hexes against tets: the NC faces tie hanging mid-edge nodes; clamped at x = 0, and
  // u_z fixed alone along an edge at the far end (partly fixed nodes keep their row).
  MixedMesh mesh = make_box_mesh({100, 10, 10}, 6, 2, 2, [](int i, int, int) {
    return i < 3 ? CubeSpec{CubeFill::Hex} : CubeSpec{CubeFill::Tets};
  });
  flag_nonconformal_quads(mesh);
  raise_to_order2(mesh, nullptr);
  const std::vector<std::uint8_t> fixed = select_fixed_dofs(mesh, {"x<1e-6", "x>99.999&z<1e-6@z"});
  const SolidMaterials mats{Material{"steel", 210e9, 0.3, 7850}};
  const double length_scale = 1e-3;

  ensure_petsc();
  const NodeTies ties = nc_face_ties(mesh, fixed);
  ASSERT_GT(ties.count, 0);
  const DofLayout L = make_layout(mesh, fixed, ties, 0, 1);
  const std::vector<const Material*> cell_mat = cell_materials(mesh, mats);
  const double sigma = -0.3 * stiffness_scale(mesh, cell_mat, length_scale);
  Matrices it;
  double volume = 0;
  const double mass =
      assemble(mesh, fixed, ties, L, length_scale, false, cell_mat, sigma, 1e3, it, volume);

  const DofMap dofs = number_free_dofs(mesh, fixed);
  const SystemMatrices direct = assemble_system(mesh, mats, dofs, length_scale);
  EXPECT_NEAR(mass, direct.mass, 1e-12 * direct.mass);
  EXPECT_NEAR(volume, direct.volume, 1e-12 * direct.volume);
  const Eigen::MatrixXd Kd =
      Eigen::MatrixXd(SparseMatrix(direct.K.selfadjointView<Eigen::Lower>()));
  const Eigen::MatrixXd Md =
      Eigen::MatrixXd(SparseMatrix(direct.M.selfadjointView<Eigen::Lower>()));

  long fixed_k = 0, fixed_m = 0, partly_fixed = 0;
  for (long p = 0; p < static_cast<long>(L.order.size()); ++p)
    for (int a = 0; a < 3; ++a) partly_fixed += fixed[3 * L.order[p] + a];
  ASSERT_GT(partly_fixed, 0);
  const Eigen::MatrixXd K = to_equations(it.K, L, dofs, false, fixed_k);
  const Eigen::MatrixXd M = to_equations(it.M, L, dofs, true, fixed_m);
  EXPECT_EQ(fixed_k, partly_fixed);
  EXPECT_EQ(fixed_m, partly_fixed);
  EXPECT_LT(worst_difference(M, Md), 1e-12);
  EXPECT_LT(worst_difference(K, Kd - sigma * Md), 1e-12);
}

}  // namespace
}  // namespace hexfem
