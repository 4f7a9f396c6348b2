#include "fem/jacobian_bounds.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <limits>
#include <utility>
#include <vector>

#include "fem/element.hpp"

namespace hexfem {

namespace {

double binomial(int n, int k) {
  double b = 1;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

double power(double x, int k) {
  double p = 1;
  for (int i = 0; i < k; ++i) p *= x;
  return p;
}

// hex20: det J has degree <= 5 in each of ξ, η, ζ (x_ξ is of degree 1 in ξ and 2 in η, ζ; the
// three columns multiply). On t = (ξ + 1) / 2 at t_i = i / 5 the Bernstein collocation matrix A
// (A_ik = B_k(t_i)) is inverted once; the coefficients are A⁻¹ ⊗ A⁻¹ ⊗ A⁻¹ applied to the samples.
constexpr int kHexDegree = 5, kHexPoints = kHexDegree + 1;

struct HexTable {
  std::vector<ShapeValues> shape;  // at the 6 x 6 x 6 points, i fastest
  Eigen::Matrix<double, kHexPoints, kHexPoints> inverse;
};

const HexTable& hex_table() {
  static const HexTable table = [] {
    HexTable t;
    Eigen::Matrix<double, kHexPoints, kHexPoints> A;
    for (int i = 0; i < kHexPoints; ++i)
      for (int k = 0; k < kHexPoints; ++k) {
        const double x = static_cast<double>(i) / kHexDegree;
        A(i, k) = binomial(kHexDegree, k) * power(x, k) * power(1 - x, kHexDegree - k);
      }
    t.inverse = A.inverse();
    for (int l = 0; l < kHexPoints; ++l)
      for (int j = 0; j < kHexPoints; ++j)
        for (int i = 0; i < kHexPoints; ++i) {
          ShapeValues s;
          hex20_shape(
              {2.0 * i / kHexDegree - 1, 2.0 * j / kHexDegree - 1, 2.0 * l / kHexDegree - 1}, s);
          t.shape.push_back(s);
        }
    return t;
  }();
  return table;
}

// Bernstein coefficients of det J over the box lo..hi (reference coordinates) from its values at
// the box's 6 x 6 x 6 points; returns their minimum and the largest value (the box's samples).
std::pair<double, double> hex20_box(const Vec3* x, const Vec3& lo, const Vec3& hi) {
  const HexTable& t = hex_table();
  constexpr int n = kHexPoints;
  std::array<double, n * n * n> v, w;
  double top = -std::numeric_limits<double>::infinity();
  for (int p = 0; p < n * n * n; ++p) {
    const int i = p % n, j = (p / n) % n, l = p / (n * n);
    const double f[3] = {static_cast<double>(i) / kHexDegree, static_cast<double>(j) / kHexDegree,
                         static_cast<double>(l) / kHexDegree};
    Vec3 xi;
    for (int d = 0; d < 3; ++d) xi[d] = lo[d] + f[d] * (hi[d] - lo[d]);
    ShapeValues s;
    if (lo == Vec3{-1, -1, -1} && hi == Vec3{1, 1, 1})
      s = t.shape[p];
    else
      hex20_shape(xi, s);
    top = std::max(top, v[p] = jacobian_determinant(s, x));
  }
  // Along i, then j, then l: c = A⁻¹ v on each line.
  for (int axis = 0; axis < 3; ++axis) {
    const int stride = axis == 0 ? 1 : axis == 1 ? n : n * n;
    for (int p = 0; p < n * n * n; ++p) {
      const int pos = (p / stride) % n, base = p - pos * stride;
      double c = 0;
      for (int k = 0; k < n; ++k) c += t.inverse(pos, k) * v[base + k * stride];
      w[p] = c;
    }
    v = w;
  }
  return {*std::min_element(v.begin(), v.end()), top};
}

// The bound is refined where it does not prove det J > 0: such a box (or tet) is split in 8, down
// to kMax*Depth levels (the coefficients converge to the values as the parts shrink).
constexpr int kMaxHexDepth = 2, kMaxTetDepth = 3;

double hex20_refined(const Vec3* x, const Vec3& lo, const Vec3& hi, double lower, int depth) {
  if (lower > 0 || depth >= kMaxHexDepth) return lower;
  double out = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    Vec3 a, b;
    for (int d = 0; d < 3; ++d) {
      const double mid = (lo[d] + hi[d]) / 2;
      a[d] = (k >> d) & 1 ? mid : lo[d];
      b[d] = (k >> d) & 1 ? hi[d] : mid;
    }
    out = std::min(out, hex20_refined(x, a, b, hex20_box(x, a, b).first, depth + 1));
  }
  return std::max(out, lower);  // each sub-box's bound is at least its parent's
}

JacobianBound hex20_bound(const Vec3* x) {
  const Vec3 lo{-1, -1, -1}, hi{1, 1, 1};
  const auto [lower, top] = hex20_box(x, lo, hi);
  return {hex20_refined(x, lo, hi, lower, 0), top};
}

// tet10: det J is a cubic in the barycentric coordinates; its 20 Bernstein coefficients from
// its values at the 20 points λ = α / 3.
constexpr int kTetDegree = 3, kTetCoefficients = 20;

struct TetTable {
  std::vector<ShapeValues> shape;
  std::vector<std::array<int, 4>> alpha;  // the multi-indices, in the order of shape
  Eigen::Matrix<double, kTetCoefficients, kTetCoefficients> inverse;
};

const TetTable& tet_table() {
  static const TetTable table = [] {
    TetTable t;
    std::vector<std::array<int, 4>> alpha;
    for (int a = 0; a <= kTetDegree; ++a)
      for (int b = 0; a + b <= kTetDegree; ++b)
        for (int c = 0; a + b + c <= kTetDegree; ++c)
          alpha.push_back({kTetDegree - a - b - c, a, b, c});
    Eigen::Matrix<double, kTetCoefficients, kTetCoefficients> M;
    for (int p = 0; p < kTetCoefficients; ++p) {
      std::array<double, 4> lambda;
      for (int i = 0; i < 4; ++i) lambda[i] = static_cast<double>(alpha[p][i]) / kTetDegree;
      ShapeValues s;
      tet10_shape({lambda[1], lambda[2], lambda[3]}, s);  // reference x = λ1, y = λ2, z = λ3
      t.shape.push_back(s);
      for (int q = 0; q < kTetCoefficients; ++q) {
        double b = 6;  // 3! / (α0! α1! α2! α3!)
        for (int i = 0; i < 4; ++i)
          for (int f = 2; f <= alpha[q][i]; ++f) b /= f;
        for (int i = 0; i < 4; ++i) b *= power(lambda[i], alpha[q][i]);
        M(p, q) = b;
      }
    }
    t.inverse = M.inverse();
    t.alpha = alpha;
    return t;
  }();
  return table;
}

// The same for a tet10 over the sub-tetrahedron with reference vertices P[0..3]: its 20
// coefficients from det J at the points sum(α_i P_i) / 3.
std::pair<double, double> tet10_part(const Vec3* x, const std::array<Vec3, 4>& P, bool whole) {
  const TetTable& t = tet_table();
  Eigen::Matrix<double, kTetCoefficients, 1> v;
  double top = -std::numeric_limits<double>::infinity();
  for (int p = 0; p < kTetCoefficients; ++p) {
    ShapeValues s;
    if (whole) {
      s = t.shape[p];
    } else {
      Vec3 xi{0, 0, 0};
      for (int i = 0; i < 4; ++i)
        for (int d = 0; d < 3; ++d) xi[d] += t.alpha[p][i] * P[i][d] / kTetDegree;
      tet10_shape(xi, s);
    }
    top = std::max(top, v(p) = jacobian_determinant(s, x));
  }
  return {(t.inverse * v).minCoeff(), top};
}

Vec3 half(const Vec3& a, const Vec3& b) {
  return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
}

double tet10_refined(const Vec3* x, const std::array<Vec3, 4>& P, double lower, int depth) {
  if (lower > 0 || depth >= kMaxTetDepth) return lower;
  // Red refinement: four corner tets and the octahedron cut along m02-m13 into four.
  const Vec3 m01 = half(P[0], P[1]), m02 = half(P[0], P[2]), m03 = half(P[0], P[3]),
             m12 = half(P[1], P[2]), m13 = half(P[1], P[3]), m23 = half(P[2], P[3]);
  const std::array<std::array<Vec3, 4>, 8> parts = {{{P[0], m01, m02, m03},
                                                     {m01, P[1], m12, m13},
                                                     {m02, m12, P[2], m23},
                                                     {m03, m13, m23, P[3]},
                                                     {m02, m13, m01, m12},
                                                     {m02, m13, m12, m23},
                                                     {m02, m13, m23, m03},
                                                     {m02, m13, m03, m01}}};
  double out = std::numeric_limits<double>::infinity();
  for (const auto& Q : parts) {
    out = std::min(out, tet10_refined(x, Q, tet10_part(x, Q, false).first, depth + 1));
  }
  return std::max(out, lower);
}

JacobianBound tet10_bound(const Vec3* x) {
  const std::array<Vec3, 4> P = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  const auto [lower, top] = tet10_part(x, P, true);
  return {tet10_refined(x, P, lower, 0), top};
}

}  // namespace

std::optional<JacobianBound> order2_jacobian_bound(CellKind kind, const Vec3* x) {
  if (kind == CellKind::Hex8) return hex20_bound(x);
  if (kind == CellKind::Tet4) return tet10_bound(x);
  return std::nullopt;
}

}  // namespace hexfem
