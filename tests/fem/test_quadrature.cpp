// Quadrature rules against closed-form integrals of monomials over each reference cell.
#include <gtest/gtest.h>

#include <cmath>

#include "fem/quadrature.hpp"

namespace hexfem {
namespace {

double factorial(int n) {
  return std::tgamma(n + 1.0);
}

double integrate(const QuadRule& rule, int a, int b, int c) {
  double s = 0;
  for (const QuadPoint& p : rule)
    s += p.w * std::pow(p.xi[0], a) * std::pow(p.xi[1], b) * std::pow(p.xi[2], c);
  return s;
}

// ∫ over [-1,1] of x^a.
double line(int a) {
  return a % 2 ? 0.0 : 2.0 / (a + 1);
}
// Simplex integrals a! b! c! / (a+b+c+d)! for dimension d.
double tet(int a, int b, int c) {
  return factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
}
double tri(int a, int b) {
  return factorial(a) * factorial(b) / factorial(a + b + 2);
}
// Pyramid: the square [-(1-ζ),(1-ζ)]^2 at height ζ; ∫ (1-ζ)^(a+b+2) ζ^c = Beta(c+1, a+b+3).
double pyramid(int a, int b, int c) {
  if (a % 2 || b % 2) return 0.0;
  return 4.0 / ((a + 1) * (b + 1)) * factorial(c) * factorial(a + b + 2) / factorial(a + b + c + 3);
}

TEST(Quadrature, GaussJacobiTwoPointAlpha2MatchesHandDerivation) {
  // Orthogonal polynomial for (1-t)^2 on [-1,1]: t^2 + 2t/3 - 1/15.
  const Rule1D r = gauss_jacobi(2, 2.0, 0.0);
  EXPECT_NEAR(r.x[0], -1.0 / 3 - std::sqrt(8.0 / 45), 1e-14);
  EXPECT_NEAR(r.x[1], -1.0 / 3 + std::sqrt(8.0 / 45), 1e-14);
  EXPECT_NEAR(r.w[0] + r.w[1], 8.0 / 3, 1e-14);
  EXPECT_NEAR(r.w[0] * r.x[0] + r.w[1] * r.x[1], -4.0 / 3, 1e-14);
}

TEST(Quadrature, GaussLegendreExactToDegree2nMinus1) {
  for (int n = 1; n <= 6; ++n) {
    const Rule1D r = gauss_legendre(n);
    for (int a = 0; a <= 2 * n; ++a) {
      double s = 0;
      for (int i = 0; i < n; ++i) s += r.w[i] * std::pow(r.x[i], a);
      if (a <= 2 * n - 1)
        EXPECT_NEAR(s, line(a), 1e-13) << "n=" << n << " a=" << a;
      else
        EXPECT_GT(std::abs(s - line(a)), 1e-6) << "n=" << n << " a=" << a;
    }
  }
}

TEST(Quadrature, CollapsedRulesExactOnSimplexAndPyramid) {
  for (int n = 1; n <= 4; ++n) {
    const QuadRule t = tet_rule(n), p = pyramid_rule(n), tr = triangle_rule(n);
    const QuadRule h = hex_rule(n);
    for (int a = 0; a <= 2 * n - 1; ++a)
      for (int b = 0; a + b <= 2 * n - 1; ++b)
        for (int c = 0; a + b + c <= 2 * n - 1; ++c) {
          EXPECT_NEAR(integrate(t, a, b, c), tet(a, b, c), 1e-14) << n << ":" << a << b << c;
          EXPECT_NEAR(integrate(p, a, b, c), pyramid(a, b, c), 1e-14) << n << ":" << a << b << c;
          EXPECT_NEAR(integrate(h, a, b, c), line(a) * line(b) * line(c), 1e-14);
          if (c == 0) {
            EXPECT_NEAR(integrate(tr, a, b, 0), tri(a, b), 1e-14);
          }
        }
  }
}

TEST(Quadrature, ProductionRulesHaveTheirDegree) {
  // Tet 4-point and triangle 3-point rules: every monomial of degree <= 2.
  for (int a = 0; a <= 2; ++a)
    for (int b = 0; a + b <= 2; ++b) {
      EXPECT_NEAR(integrate(triangle_rule(), a, b, 0), tri(a, b), 1e-15);
      for (int c = 0; a + b + c <= 2; ++c)
        EXPECT_NEAR(integrate(tet_rule(), a, b, c), tet(a, b, c), 1e-15);
    }
  EXPECT_GT(std::abs(integrate(tet_rule(), 3, 0, 0) - tet(3, 0, 0)), 1e-6);
  // Wedge 3x2: triangle degree 2 times ζ degree 3.
  const QuadRule w = wedge_rule(2);
  for (int a = 0; a <= 2; ++a)
    for (int b = 0; a + b <= 2; ++b)
      for (int c = 0; c <= 3; ++c) EXPECT_NEAR(integrate(w, a, b, c), tri(a, b) * line(c), 1e-15);
  // Weights sum to the reference volumes.
  EXPECT_NEAR(integrate(hex_rule(2), 0, 0, 0), 8.0, 1e-14);
  EXPECT_NEAR(integrate(w, 0, 0, 0), 1.0, 1e-14);
  EXPECT_NEAR(integrate(pyramid_rule(2), 0, 0, 0), 4.0 / 3, 1e-14);
  EXPECT_NEAR(integrate(tet_rule(), 0, 0, 0), 1.0 / 6, 1e-15);
}

TEST(Quadrature, PyramidRuleNeverSamplesTheApex) {
  for (int n = 1; n <= 6; ++n)
    for (const QuadPoint& p : pyramid_rule(n)) EXPECT_LT(p.xi[2], 1.0 - 1e-3);
}

}  // namespace
}  // namespace hexfem
