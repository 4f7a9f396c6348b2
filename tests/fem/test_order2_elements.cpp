// The order-2 elements (hex20, wedge15, pyramid13, tet10): interpolation at the nodes, partition
// of unity, derivatives against finite differences, completeness to degree 2, exactness of the
// production rules on affine cells against much finer rules, and a stiffness with exactly six
// zero-energy modes.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "fem/element.hpp"
#include "fem_test_util.hpp"

namespace hexfem {
namespace {

const Material kMat{"test", 1000.0, 0.3, 2.0};

// A random interior point of the reference cell (away from the pyramid apex).
Vec3 random_point(CellKind kind, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.02, 0.98);
  for (;;) {
    const Vec3 p{u(rng), u(rng), u(rng)};
    switch (kind) {
      case CellKind::Hex8:
        return {2 * p[0] - 1, 2 * p[1] - 1, 2 * p[2] - 1};
      case CellKind::Wedge6:
        if (p[0] + p[1] < 1) return {p[0], p[1], 2 * p[2] - 1};
        break;
      case CellKind::Pyramid5: {
        const double z = 0.95 * p[2];
        return {(2 * p[0] - 1) * (1 - z), (2 * p[1] - 1) * (1 - z), z};
      }
      case CellKind::Tet4:
        if (p[0] + p[1] + p[2] < 1) return p;
        break;
    }
  }
}

TEST(Order2Elements, InterpolateAtTheirNodes) {
  for (CellKind kind : test::kAllKinds) {
    const std::vector<Vec3> nodes = reference_nodes(kind, 2);
    ASSERT_EQ(static_cast<int>(nodes.size()), num_nodes(kind, 2));
    for (std::size_t j = 0; j < nodes.size(); ++j) {
      Vec3 p = nodes[j];
      const bool apex = kind == CellKind::Pyramid5 && j == 4;
      if (apex) p[2] = 1 - 1e-9;  // 0/0 at the apex itself: the limit along the axis
      ShapeValues s;
      shape_functions(kind, 2, p, s);
      ASSERT_EQ(s.n, num_nodes(kind, 2));
      for (int i = 0; i < s.n; ++i)
        EXPECT_NEAR(s.N[i], i == static_cast<int>(j) ? 1.0 : 0.0, apex ? 1e-8 : 1e-14)
            << kind_name(kind, 2) << " N" << i << " at node " << j;
    }
  }
}

TEST(Order2Elements, DerivativesMatchFiniteDifferencesAndSumToZero) {
  std::mt19937 rng(7);
  for (CellKind kind : test::kAllKinds)
    for (int trial = 0; trial < 20; ++trial) {
      const Vec3 p = random_point(kind, rng);
      ShapeValues s;
      shape_functions(kind, 2, p, s);
      double sum = 0, dsum[3] = {};
      for (int i = 0; i < s.n; ++i) {
        sum += s.N[i];
        for (int d = 0; d < 3; ++d) dsum[d] += s.dN[i][d];
      }
      EXPECT_NEAR(sum, 1.0, 1e-14) << kind_name(kind, 2);
      for (int d = 0; d < 3; ++d) EXPECT_NEAR(dsum[d], 0.0, 1e-13) << kind_name(kind, 2);
      const double h = 1e-6;
      for (int d = 0; d < 3; ++d) {
        Vec3 a = p, b = p;
        a[d] -= h;
        b[d] += h;
        ShapeValues sa, sb;
        shape_functions(kind, 2, a, sa);
        shape_functions(kind, 2, b, sb);
        for (int i = 0; i < s.n; ++i)
          EXPECT_NEAR(s.dN[i][d], (sb.N[i] - sa.N[i]) / (2 * h), 1e-8)
              << kind_name(kind, 2) << " dN" << i << "/dx" << d;
      }
    }
}

// Σ N_i q(x_i) = q(x) for every monomial q of degree <= 2: the space holds all quadratics.
TEST(Order2Elements, ReproduceEveryQuadratic) {
  std::mt19937 rng(11);
  const auto mono = [](const Vec3& x, int k) {
    static constexpr int e[10][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0},
                                     {0, 2, 0}, {0, 0, 2}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
    return std::pow(x[0], e[k][0]) * std::pow(x[1], e[k][1]) * std::pow(x[2], e[k][2]);
  };
  for (CellKind kind : test::kAllKinds) {
    const std::vector<Vec3> nodes = reference_nodes(kind, 2);
    for (int trial = 0; trial < 20; ++trial) {
      const Vec3 p = random_point(kind, rng);
      ShapeValues s;
      shape_functions(kind, 2, p, s);
      for (int k = 0; k < 10; ++k) {
        double v = 0;
        for (int i = 0; i < s.n; ++i) v += s.N[i] * mono(nodes[i], k);
        EXPECT_NEAR(v, mono(p, k), 1e-13) << kind_name(kind, 2) << " monomial " << k;
      }
    }
  }
}

// The nodes of an affine image of the reference cell (mid-edge nodes at the midpoints).
std::vector<Vec3> affine_element(CellKind kind, std::mt19937& rng) {
  return test::affine_image(reference_nodes(kind, 2), rng);
}

QuadRule fine_rule(CellKind kind) {
  switch (kind) {
    case CellKind::Hex8:
      return hex_rule(7);
    case CellKind::Wedge6:
      return wedge_rule(7, 7);
    case CellKind::Pyramid5:
      return pyramid_rule(8);
    case CellKind::Tet4:
      return tet_rule(7);
  }
  return {};
}

TEST(Order2Elements, ProductionRuleExactOnAffineCells) {
  std::mt19937 rng(3);
  for (CellKind kind : test::kAllKinds) {
    const std::vector<Vec3> x = affine_element(kind, rng);
    const int n = num_nodes(kind, 2), nd = 3 * n;
    std::vector<double> K(nd * nd), m(n * n), Kf(nd * nd), mf(n * n);
    ASSERT_GT(element_matrices(reference_element(kind, 2), x.data(), kMat, K.data(), m.data()), 0);
    const ReferenceElement fine = tabulate(kind, 2, fine_rule(kind));
    element_matrices(fine, x.data(), kMat, Kf.data(), mf.data());
    double kmax = 0, mmax = 0, kerr = 0, merr = 0;
    for (int i = 0; i < nd * nd; ++i) {
      kmax = std::max(kmax, std::abs(Kf[i]));
      kerr = std::max(kerr, std::abs(K[i] - Kf[i]));
    }
    for (int i = 0; i < n * n; ++i) {
      mmax = std::max(mmax, std::abs(mf[i]));
      merr = std::max(merr, std::abs(m[i] - mf[i]));
    }
    EXPECT_LT(kerr, 1e-12 * kmax) << kind_name(kind, 2) << " stiffness";
    EXPECT_LT(merr, 1e-12 * mmax) << kind_name(kind, 2) << " mass";
  }
}

TEST(Order2Elements, SixZeroEnergyModesAndMassIsRhoV) {
  std::mt19937 rng(5);
  for (CellKind kind : test::kAllKinds) {
    std::vector<Vec3> x = affine_element(kind, rng);
    test::perturb(x, 0.03, rng);  // a distorted, curved element
    const int n = num_nodes(kind, 2), nd = 3 * n;
    std::vector<double> K(nd * nd), m(n * n);
    ASSERT_GT(element_matrices(reference_element(kind, 2), x.data(), kMat, K.data(), m.data()), 0);
    const Eigen::Map<Eigen::MatrixXd> Km(K.data(), nd, nd);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Km);
    const Eigen::VectorXd ev = eig.eigenvalues();
    const double top = ev[nd - 1];
    int zero = 0;
    for (int i = 0; i < nd; ++i) zero += std::abs(ev[i]) < 1e-10 * top;
    EXPECT_EQ(zero, 6) << kind_name(kind, 2) << " smallest nonzero " << ev[6] / top;
    // Σ m_ij = ρ ∫ Σ N_i Σ N_j = ρ V; V from the fine rule.
    const ReferenceElement fine = tabulate(kind, 2, fine_rule(kind));
    std::vector<double> Kf(nd * nd), mf(n * n);
    element_matrices(fine, x.data(), kMat, Kf.data(), mf.data());
    double sum = 0, sumf = 0;
    for (int i = 0; i < n * n; ++i) {
      sum += m[i];
      sumf += mf[i];
    }
    EXPECT_NEAR(sum, sumf, 1e-6 * sumf) << kind_name(kind, 2);
  }
}

}  // namespace
}  // namespace hexfem
