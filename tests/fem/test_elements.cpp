// Element-level checks per kind: exact integration on undistorted cells (against a high-order
// rule), linear fields reproduced exactly, six zero-energy modes, mass = ρ·V·3.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cstdio>

#include "fem/element.hpp"
#include "fem_test_util.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {
namespace {

using test::kAllKinds;

const Material kSteel{"steel", 210e9, 0.3, 7850};

QuadRule high_order_rule(CellKind kind) {
  switch (kind) {
    case CellKind::Hex8:
      return hex_rule(6);
    case CellKind::Wedge6:
      return wedge_rule(6, 6);
    case CellKind::Pyramid5:
      return pyramid_rule(6);
    case CellKind::Tet4:
      return tet_rule(6);
  }
  return {};
}

struct Matrices {
  Eigen::MatrixXd K, m;
  double min_det;
};
Matrices matrices(const ReferenceElement& ref, const std::vector<Vec3>& x) {
  Matrices out{Eigen::MatrixXd(3 * ref.n, 3 * ref.n), Eigen::MatrixXd(ref.n, ref.n), 0};
  std::vector<double> K(9 * ref.n * ref.n), m(ref.n * ref.n);
  out.min_det = element_matrices(ref, x.data(), kSteel, K.data(), m.data());
  for (int i = 0; i < 3 * ref.n; ++i)
    for (int j = 0; j < 3 * ref.n; ++j) out.K(i, j) = K[i * 3 * ref.n + j];
  for (int i = 0; i < ref.n; ++i)
    for (int j = 0; j < ref.n; ++j) out.m(i, j) = m[i * ref.n + j];
  return out;
}

std::vector<Vec3> shapes(CellKind kind, bool distorted, std::mt19937& rng) {
  std::vector<Vec3> x = test::affine_image(test::reference_corners(kind), rng);
  if (distorted) test::perturb(x, 0.12, rng);
  return x;
}

TEST(Elements, ProductionRuleExactOnUndistortedCells) {
  std::mt19937 rng(7);
  for (CellKind kind : kAllKinds)
    for (int trial = 0; trial < 5; ++trial) {
      const std::vector<Vec3> x = shapes(kind, false, rng);
      const Matrices a = matrices(reference_element(kind), x);
      const Matrices b = matrices(tabulate(kind, high_order_rule(kind)), x);
      EXPECT_LT((a.K - b.K).cwiseAbs().maxCoeff(), 1e-12 * b.K.cwiseAbs().maxCoeff())
          << kind_name(kind);
      EXPECT_LT((a.m - b.m).cwiseAbs().maxCoeff(), 1e-12 * b.m.cwiseAbs().maxCoeff())
          << kind_name(kind);
    }
}

TEST(Elements, PyramidMassNeedsTheJacobiRule) {
  // A collapsed 2x2x2 Gauss-Legendre rule (a degenerate C3D8) gets the pyramid mass wrong: the
  // check above is not vacuous.
  std::mt19937 rng(3);
  const std::vector<Vec3> x = shapes(CellKind::Pyramid5, false, rng);
  QuadRule legendre;
  const Rule1D g = gauss_legendre(2);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const double z = (1 + g.x[k]) / 2;
        legendre.push_back({{g.x[i] * (1 - z), g.x[j] * (1 - z), z},
                            g.w[i] * g.w[j] * g.w[k] * (1 - z) * (1 - z) / 2});
      }
  const Matrices a = matrices(tabulate(CellKind::Pyramid5, legendre), x);
  const Matrices b = matrices(tabulate(CellKind::Pyramid5, high_order_rule(CellKind::Pyramid5)), x);
  EXPECT_GT((a.m - b.m).cwiseAbs().maxCoeff(), 1e-3 * b.m.cwiseAbs().maxCoeff());
}

TEST(Elements, LinearFieldGivesExactStrainUndistortedAndDistorted) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  for (CellKind kind : kAllKinds)
    for (bool distorted : {false, true}) {
      const std::vector<Vec3> x = shapes(kind, distorted, rng);
      double G[3][3], c[3];
      for (int a = 0; a < 3; ++a) {
        c[a] = u(rng);
        for (int b = 0; b < 3; ++b) G[a][b] = u(rng);
      }
      std::vector<double> disp;
      for (const Vec3& p : x)
        for (int a = 0; a < 3; ++a)
          disp.push_back(c[a] + G[a][0] * p[0] + G[a][1] * p[1] + G[a][2] * p[2]);
      const double exact[6] = {G[0][0],           G[1][1],           G[2][2],
                               G[0][1] + G[1][0], G[1][2] + G[2][1], G[2][0] + G[0][2]};
      for (const auto& eps : element_strains(reference_element(kind), x.data(), disp.data()))
        for (int k = 0; k < 6; ++k)
          EXPECT_NEAR(eps[k], exact[k], 1e-15)
              << kind_name(kind) << (distorted ? " distorted" : "");
    }
}

TEST(Elements, ExactlySixZeroEnergyModes) {
  std::mt19937 rng(5);
  for (CellKind kind : kAllKinds)
    for (bool distorted : {false, true}) {
      const std::vector<Vec3> x = shapes(kind, distorted, rng);
      const Matrices mat = matrices(reference_element(kind), x);
      ASSERT_GT(mat.min_det, 0);
      const Eigen::VectorXd ev =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(mat.K).eigenvalues();
      const double top = ev.maxCoeff();
      int zero = 0;
      for (int i = 0; i < ev.size(); ++i) zero += std::abs(ev[i]) < 1e-10 * top;
      EXPECT_EQ(zero, 6) << kind_name(kind) << (distorted ? " distorted" : "");
      std::printf("%-8s %-10s eigenvalues of K_e: max |λ1..6| / λmax = %.1e, λ7 / λmax = %.1e\n",
                  kind_name(kind), distorted ? "distorted" : "affine",
                  ev.head(6).cwiseAbs().maxCoeff() / top, ev[6] / top);
      EXPECT_GT(ev[6], 1e-4 * top) << kind_name(kind) << (distorted ? " distorted" : "");
    }
}

TEST(Elements, MassSumsToThreeRhoV) {
  std::mt19937 rng(13);
  for (CellKind kind : kAllKinds)
    for (bool distorted : {false, true}) {
      const std::vector<Vec3> x = shapes(kind, distorted, rng);
      const Matrices mat = matrices(reference_element(kind), x);
      // Σ_ij m_ij for one component; the 3n x 3n mass is m ⊗ I3.
      const double total = 3 * mat.m.sum();
      const double v = volume(kind, x.data());  // quality.hpp's exact volume, independent code
      // Undistorted: exact. Distorted pyramids/hexes have non-planar faces whose volume the rule
      // integrates exactly only for the trilinear/bilinear maps (same as quality's).
      std::printf("%-8s %-10s Σ M_e / (3 ρ V) - 1 = %.1e\n", kind_name(kind),
                  distorted ? "distorted" : "affine", total / (3 * kSteel.rho * v) - 1);
      EXPECT_NEAR(total, 3 * kSteel.rho * v, 1e-12 * total)
          << kind_name(kind) << (distorted ? " distorted" : "");
    }
}

}  // namespace
}  // namespace hexfem
