#include "fem/quadrature.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "mesher/mesh/error.hpp"

namespace hexfem {

Rule1D gauss_jacobi(int n, double alpha, double beta) {
  if (n < 1 || alpha <= -1 || beta <= -1) throw Error("gauss_jacobi: bad parameters");
  // Golub-Welsch: the nodes are the eigenvalues of the Jacobi matrix of the monic recurrence,
  // the weights mu0 * (first eigenvector component)^2.
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, n);
  const double ab = alpha + beta;
  for (int k = 0; k < n; ++k) {
    const double s = 2.0 * k + ab;
    J(k, k) = k == 0 ? (beta - alpha) / (ab + 2) : (beta * beta - alpha * alpha) / (s * (s + 2));
    if (k > 0) {
      const double b2 = 4.0 * k * (k + alpha) * (k + beta) * (k + ab) / (s * s * (s + 1) * (s - 1));
      J(k, k - 1) = J(k - 1, k) = std::sqrt(b2);
    }
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(J);
  const double mu0 = std::exp((ab + 1) * std::log(2.0) + std::lgamma(alpha + 1) +
                              std::lgamma(beta + 1) - std::lgamma(ab + 2));
  Rule1D r;
  for (int k = 0; k < n; ++k) {
    r.x.push_back(eig.eigenvalues()(k));
    r.w.push_back(mu0 * eig.eigenvectors()(0, k) * eig.eigenvectors()(0, k));
  }
  return r;
}

Rule1D gauss_legendre(int n) {
  return gauss_jacobi(n, 0.0, 0.0);
}

// The n^3 product of three 1D rules, each point (u, v, t) with weight w mapped by `map` to the
// reference element's point and weight (the collapsed rules of the tet and the pyramid).
template <class Map>
QuadRule product_rule(const Rule1D& gu, const Rule1D& gv, const Rule1D& gt, Map map) {
  QuadRule rule;
  for (std::size_t k = 0; k < gt.x.size(); ++k)
    for (std::size_t j = 0; j < gv.x.size(); ++j)
      for (std::size_t i = 0; i < gu.x.size(); ++i)
        rule.push_back(map(gu.x[i], gv.x[j], gt.x[k], gu.w[i] * gv.w[j] * gt.w[k]));
  return rule;
}

QuadRule hex_rule(int n) {
  const Rule1D g = gauss_legendre(n);
  return product_rule(g, g, g, [](double u, double v, double t, double w) {
    return QuadPoint{{u, v, t}, w};
  });
}

QuadRule triangle_rule(int n) {
  if (n <= 0) {
    return {{{1.0 / 6, 1.0 / 6, 0}, 1.0 / 6},
            {{2.0 / 3, 1.0 / 6, 0}, 1.0 / 6},
            {{1.0 / 6, 2.0 / 3, 0}, 1.0 / 6}};
  }
  // η = (1+v)/2, ξ = (1+u)/2 (1-η): dξdη = (1-v)/8 du dv, the (1-v) taken by Gauss-Jacobi(1,0).
  const Rule1D gu = gauss_legendre(n);
  const Rule1D gv = gauss_jacobi(n, 1.0, 0.0);
  QuadRule rule;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double eta = (1 + gv.x[j]) / 2;
      rule.push_back({{(1 + gu.x[i]) / 2 * (1 - eta), eta, 0}, gu.w[i] * gv.w[j] / 8});
    }
  return rule;
}

QuadRule wedge_rule(int n_line, int n_triangle) {
  const QuadRule tri = triangle_rule(n_triangle);
  const Rule1D g = gauss_legendre(n_line);
  QuadRule rule;
  for (int k = 0; k < n_line; ++k)
    for (const QuadPoint& p : tri) rule.push_back({{p.xi[0], p.xi[1], g.x[k]}, p.w * g.w[k]});
  return rule;
}

QuadRule tet_rule(int n) {
  if (n <= 0) {
    const double a = (5 - std::sqrt(5.0)) / 20, b = (5 + 3 * std::sqrt(5.0)) / 20;
    return {
        {{a, a, a}, 1.0 / 24}, {{b, a, a}, 1.0 / 24}, {{a, b, a}, 1.0 / 24}, {{a, a, b}, 1.0 / 24}};
  }
  // ζ = (1+t)/2, η = (1+v)/2 (1-ζ), ξ = (1+u)/2 (1-η-ζ): dV = (1-t)^2 (1-v)/64 du dv dt.
  return product_rule(gauss_legendre(n), gauss_jacobi(n, 1.0, 0.0), gauss_jacobi(n, 2.0, 0.0),
                      [](double u, double v, double t, double w) {
                        const double zeta = (1 + t) / 2;
                        const double eta = (1 + v) / 2 * (1 - zeta);
                        const double xi = (1 + u) / 2 * (1 - eta - zeta);
                        return QuadPoint{{xi, eta, zeta}, w / 64};
                      });
}

QuadRule pyramid_rule(int n) {
  const Rule1D g = gauss_legendre(n);
  return product_rule(g, g, gauss_jacobi(n, 2.0, 0.0), [](double u, double v, double t, double w) {
    const double zeta = (1 + t) / 2;
    return QuadPoint{{u * (1 - zeta), v * (1 - zeta), zeta}, w / 8};
  });
}

}  // namespace hexfem
