#include "mesher/frame_field_smooth.hpp"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

// 4! / (a! b! c!) for each monomial.
std::array<double, 15> make_multinomials() {
  static constexpr int kFact[5] = {1, 1, 2, 6, 24};
  std::array<double, 15> m{};
  const auto& e = quartic_exponents();
  for (int i = 0; i < 15; ++i) m[i] = 24.0 / (kFact[e[i][0]] * kFact[e[i][1]] * kFact[e[i][2]]);
  return m;
}

// Powers 0..4 of each coordinate.
std::array<std::array<double, 5>, 3> powers(const Vec3& x) {
  std::array<std::array<double, 5>, 3> p{};
  for (int a = 0; a < 3; ++a) {
    p[a][0] = 1;
    for (int k = 1; k < 5; ++k) p[a][k] = p[a][k - 1] * x[a];
  }
  return p;
}

Eigen::Vector3d quartic_gradient(const Quartic& q, const Vec3& x) {
  const auto& e = quartic_exponents();
  const auto p = powers(x);
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (int m = 0; m < 15; ++m) {
    const int a = e[m][0], b = e[m][1], c = e[m][2];
    if (a > 0) g[0] += q[m] * a * p[0][a - 1] * p[1][b] * p[2][c];
    if (b > 0) g[1] += q[m] * b * p[0][a] * p[1][b - 1] * p[2][c];
    if (c > 0) g[2] += q[m] * c * p[0][a] * p[1][b] * p[2][c - 1];
  }
  return g;
}

Eigen::Matrix3d to_matrix(const Frame& f) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) m(a, i) = f[i][a];
  return m;
}

Frame to_frame(const Eigen::Matrix3d& m) {
  Frame f;
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) f[i][a] = m(a, i);
  return f;
}

// The rotation nearest to g (polar factor), right-handed. Scaled Newton iterations (Higham)
// when det g is clearly positive, several times cheaper than the SVD that handles the rest.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& g) {
  const double scale = g.norm();
  if (scale > 0 && g.determinant() > 1e-3 * scale * scale * scale) {
    Eigen::Matrix3d r = g / scale;
    for (int it = 0; it < 20; ++it) {
      const double gamma = std::cbrt(1 / r.determinant());
      const Eigen::Matrix3d next = 0.5 * (gamma * r + r.inverse().transpose() / gamma);
      const double change = (next - r).cwiseAbs().maxCoeff();
      r = next;
      if (change < 1e-13) return r;
    }
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(g, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0) u.col(2) *= -1;
  return u * v.transpose();
}

void add_scaled(Quartic& acc, const Quartic& q, double w) {
  for (int m = 0; m < 15; ++m) acc[m] += w * q[m];
}

// Conjugate gradients on the columns of b at once, in lockstep: one pass over the matrix per
// iteration for all columns (Eigen's solver takes the columns one after the other, each pass
// memory-bound). Stops when every column's residual is below tol times its |b|.
Eigen::MatrixXd solve_columns(const Eigen::SparseMatrix<double, Eigen::RowMajor>& a,
                              const Eigen::MatrixXd& b, const Eigen::MatrixXd& guess, double tol,
                              int* iterations) {
  Eigen::MatrixXd x = guess;
  Eigen::MatrixXd r = b - a * x;
  Eigen::MatrixXd p = r;
  Eigen::RowVectorXd rr = r.colwise().squaredNorm();
  const Eigen::RowVectorXd stop = (tol * tol) * b.colwise().squaredNorm().cwiseMax(1e-300);
  int it = 0;
  for (; it < 10 * static_cast<int>(b.rows()) + 100; ++it) {
    if ((rr.array() <= stop.array()).all()) break;
    const Eigen::MatrixXd ap = a * p;
    const Eigen::RowVectorXd pap = p.cwiseProduct(ap).colwise().sum();
    for (Eigen::Index c = 0; c < b.cols(); ++c) {
      if (rr[c] <= stop[c] || !(pap[c] > 0)) continue;  // this column has converged
      const double alpha = rr[c] / pap[c];
      x.col(c) += alpha * p.col(c);
      r.col(c) -= alpha * ap.col(c);
      const double next = r.col(c).squaredNorm();
      p.col(c) = r.col(c) + (next / rr[c]) * p.col(c);
      rr[c] = next;
    }
  }
  *iterations = it;
  return x;
}

}  // namespace

const std::array<std::array<int, 3>, 15>& quartic_exponents() {
  static const std::array<std::array<int, 3>, 15> e = [] {
    std::array<std::array<int, 3>, 15> out{};
    int m = 0;
    for (int a = 4; a >= 0; --a)
      for (int b = 4 - a; b >= 0; --b) out[m++] = {a, b, 4 - a - b};
    return out;
  }();
  return e;
}

Quartic frame_quartic(const Frame& f) {
  static const std::array<double, 15> multi = make_multinomials();
  const auto& e = quartic_exponents();
  Quartic q{};
  for (const Vec3& d : f) {
    const auto p = powers(d);
    for (int m = 0; m < 15; ++m) q[m] += multi[m] * p[0][e[m][0]] * p[1][e[m][1]] * p[2][e[m][2]];
  }
  return q;
}

double quartic_value(const Quartic& q, const Vec3& x) {
  const auto& e = quartic_exponents();
  const auto p = powers(x);
  double s = 0;
  for (int m = 0; m < 15; ++m) s += q[m] * p[0][e[m][0]] * p[1][e[m][1]] * p[2][e[m][2]];
  return s;
}

Frame project_quartic(const Quartic& q, const Frame& start, int iterations) {
  // R <- polar(grad f(R)), f(R) = sum_i q(R e_i): f is convex, so f(R') >= f(R) + <G, R' - R>
  // and the polar factor maximizes <G, R'>: f never decreases.
  Eigen::Matrix3d r = nearest_rotation(to_matrix(start));
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix3d g;
    for (int i = 0; i < 3; ++i) g.col(i) = quartic_gradient(q, {r(0, i), r(1, i), r(2, i)});
    const Eigen::Matrix3d next = nearest_rotation(g);
    const double change = (next - r).cwiseAbs().maxCoeff();
    r = next;
    if (change < 1e-10) break;
  }
  return to_frame(r);
}

double frame_angle(const Frame& a, const Frame& b) {
  double worst = 1;
  for (const Vec3& ai : a) {
    double best = 0;
    for (const Vec3& bj : b)
      best = std::max(best, std::abs(ai[0] * bj[0] + ai[1] * bj[1] + ai[2] * bj[2]));
    worst = std::min(worst, best);
  }
  return std::acos(std::min(1.0, worst));
}

SmoothFrameField::SmoothFrameField(const SurfaceMesh& surface, const FrameField3D& field,
                                   const SolidLocator& locator, const SmoothFrameOptions& options) {
  const auto& nodes = surface.mesh.nodes;
  if (nodes.empty()) throw Error("smooth frame field: the surface has no nodes");
  if (!(options.cell > 0) || !(options.fixed_distance >= 0))
    throw Error("smooth frame field: cell must be > 0 and fixed_distance >= 0");
  Vec3 lo = nodes[0], hi = nodes[0];
  for (const Vec3& p : nodes)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  // One cell of margin on every side: the grid's outer nodes are outside the solids (fixed),
  // so every free node has its six neighbours.
  cell_ = options.cell * field.max_size();
  for (;;) {
    std::size_t count = 1;
    for (int a = 0; a < 3; ++a) {
      dims_[a] = static_cast<int>(std::ceil((hi[a] - lo[a]) / cell_)) + 3;
      count *= static_cast<std::size_t>(dims_[a]);
    }
    if (count <= std::max<std::size_t>(options.max_nodes, 27)) break;
    cell_ *= 1.25;
  }
  for (int a = 0; a < 3; ++a) lo_[a] = lo[a] - cell_;
  const std::size_t n = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  frames_.resize(n);
  free_.assign(n, 0);
  const auto sn = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t i = 0; i < sn; ++i) {
    const Vec3 p = node_position(static_cast<std::size_t>(i));
    const std::int32_t v = field.nearest_vertex(p);
    const Vec3& x = nodes[v];
    const double d = std::sqrt((p[0] - x[0]) * (p[0] - x[0]) + (p[1] - x[1]) * (p[1] - x[1]) +
                               (p[2] - x[2]) * (p[2] - x[2]));
    frames_[i] = field.vertex_frame(v);
    bool inside = false;
    if (d >= options.fixed_distance * field.vertex_size(v)) {
      // A node on the surface (the grid aligned with a CAD face) cannot be located: it stays
      // fixed, and no exception leaves the parallel loop.
      try {
        inside = locator.locate(p) > 0;
      } catch (const Error&) {
        inside = false;
      }
    }
    free_[i] = inside;
  }
  // Harmonic extension of the fixed nodes' quartics over the free ones: 6 q_i - sum of the six
  // neighbours = 0 (the 7-point Laplacian), the fixed neighbours moved to the right-hand side.
  std::vector<std::int64_t> unknown(n, -1);
  std::vector<std::size_t> free_nodes;
  for (std::size_t i = 0; i < n; ++i)
    if (free_[i]) {
      unknown[i] = static_cast<std::int64_t>(free_nodes.size());
      free_nodes.push_back(i);
    }
  num_free_ = free_nodes.size();
  const std::size_t step[3] = {1, static_cast<std::size_t>(dims_[0]),
                               static_cast<std::size_t>(dims_[0]) * dims_[1]};
  if (num_free_ > 0) {
    const auto nf = static_cast<Eigen::Index>(num_free_);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(7 * num_free_);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nf, 15), guess(nf, 15);
    for (std::size_t u = 0; u < num_free_; ++u) {
      const std::size_t i = free_nodes[u];
      const auto row = static_cast<Eigen::Index>(u);
      triplets.emplace_back(row, row, 6.0);
      for (int a = 0; a < 3; ++a)
        for (int s = -1; s <= 1; s += 2) {
          const std::size_t j = s < 0 ? i - step[a] : i + step[a];
          if (unknown[j] >= 0) {
            triplets.emplace_back(row, static_cast<Eigen::Index>(unknown[j]), -1.0);
          } else {
            const Quartic q = frame_quartic(frames_[j]);
            for (int m = 0; m < 15; ++m) rhs(row, m) += q[m];
          }
        }
      const Quartic q0 = frame_quartic(frames_[i]);
      for (int m = 0; m < 15; ++m) guess(row, m) = q0[m];
    }
    Eigen::SparseMatrix<double, Eigen::RowMajor> lap(nf, nf);
    lap.setFromTriplets(triplets.begin(), triplets.end());
    const Eigen::MatrixXd x = solve_columns(lap, rhs, guess, 1e-6, &solver_iterations_);
    const auto snf = static_cast<std::ptrdiff_t>(num_free_);
#pragma omp parallel for schedule(dynamic, 256)
    for (std::ptrdiff_t u = 0; u < snf; ++u) {
      Quartic q;
      for (int m = 0; m < 15; ++m) q[m] = x(u, m);
      frames_[free_nodes[u]] = project_quartic(q, frames_[free_nodes[u]], 30);
    }
    // Sharpening: each free node takes the projected average of its neighbours' frames.
    std::vector<Quartic> pure;
    for (int round = 0; round < options.sharpen_rounds; ++round) {
      pure.resize(n);
      const auto sn2 = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static)
      for (std::ptrdiff_t i = 0; i < sn2; ++i) pure[i] = frame_quartic(frames_[i]);
      std::vector<Frame> next(frames_);
#pragma omp parallel for schedule(dynamic, 256)
      for (std::ptrdiff_t u = 0; u < snf; ++u) {
        const std::size_t i = free_nodes[u];
        Quartic q{};
        for (int a = 0; a < 3; ++a) {
          add_scaled(q, pure[i - step[a]], 1.0);
          add_scaled(q, pure[i + step[a]], 1.0);
        }
        next[i] = project_quartic(q, frames_[i], 30);
      }
      frames_.swap(next);
    }
  }
  quartics_.resize(n);
  for (std::size_t i = 0; i < n; ++i) quartics_[i] = frame_quartic(frames_[i]);
}

Vec3 SmoothFrameField::node_position(std::size_t i) const {
  const std::size_t nx = dims_[0], ny = dims_[1];
  const std::size_t ix = i % nx, iy = (i / nx) % ny, iz = i / (nx * ny);
  return {lo_[0] + cell_ * static_cast<double>(ix), lo_[1] + cell_ * static_cast<double>(iy),
          lo_[2] + cell_ * static_cast<double>(iz)};
}

Frame SmoothFrameField::at(const Vec3& p) const {
  int i0[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    const double s = (p[a] - lo_[a]) / cell_;
    i0[a] = std::clamp(static_cast<int>(std::floor(s)), 0, dims_[a] - 2);
    t[a] = std::clamp(s - i0[a], 0.0, 1.0);
  }
  Quartic q{};
  double best_w = -1;
  std::size_t best = 0;
  bool same = true;  // all eight corners share one frame: it is the answer, no projection
  const Frame& f0 = frames_[index(i0[0], i0[1], i0[2])];
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
    const std::size_t id = index(i0[0] + dx, i0[1] + dy, i0[2] + dz);
    same = same && frames_[id] == f0;
    add_scaled(q, quartics_[id], w);
    if (w > best_w) {
      best_w = w;
      best = id;
    }
  }
  if (same) return f0;
  return project_quartic(q, frames_[best], 8);
}

}  // namespace hexfem
