#include "mesher/volume_points_lpcvt.hpp"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <utility>

#include "mesher/mesh/error.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K>;
using Cb = CGAL::Triangulation_cell_base_with_info_3<std::int32_t, K,
                                                     CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;

// Complete homogeneous symmetric polynomial of degree n in v[0..m): the sum of all monomials of
// degree n. h_n(x) with one variable repeated is its derivative in that variable.
double complete_h(int n, const double* v, int m) {
  double h[16];
  for (int j = 0; j <= n; ++j) h[j] = j == 0 ? 1.0 : h[j - 1] * v[0];
  for (int i = 1; i < m; ++i)
    for (int j = 1; j <= n; ++j) h[j] += v[i] * h[j - 1];
  return h[n];
}

struct CellGeometry {
  Vec3 centre;
  std::array<std::int32_t, 4> vertex;
};

constexpr double kSliver =
    1e-6;  // |det B| / (|b0| |b1| |b2|) below which a cell is a sliver  // |det B| / (|b0| |b1|
           // |b2|) below which a cell is a sliver  // |det B| / (|b0| |b1| |b2|) below which a cell
           // is a sliver  // |det B| / (|b0| |b1| |b2|) below which a cell is a sliver

// Circumcentre of (x0..x3): 2 B c = r with B's rows x_a - x0, r_a = |x_a|^2 - |x0|^2, solved
// relative to x0 for accuracy.
bool circumcentre(const Vec3 (&x)[4], Vec3& c, Eigen::Matrix3d& binv) {
  Eigen::Matrix3d b;
  Eigen::Vector3d r;
  for (int a = 0; a < 3; ++a) {
    for (int d = 0; d < 3; ++d) b(a, d) = x[a + 1][d] - x[0][d];
    r(a) = 0.5 * b.row(a).squaredNorm();
  }
  // A sliver (four nearly co-circular points, as in the frontal lattice's cubes) has an
  // ill-conditioned centre: its derivative is left out, else rounding makes a gradient of 1e15.
  const double det = b.determinant();
  if (!(std::abs(det) > kSliver * b.row(0).norm() * b.row(1).norm() * b.row(2).norm()))
    return false;
  binv = b.inverse();
  const Eigen::Vector3d rel = binv * r;
  for (int d = 0; d < 3; ++d) c[d] = x[0][d] + rel(d);
  return true;
}

// The energy of one point's cell and its derivatives: direct (x_i) and through the Voronoi
// vertices (per Delaunay cell).
struct PointTerms {
  double energy = 0;
  Vec3 grad{0, 0, 0};
  std::vector<std::pair<std::int32_t, Vec3>> by_cell;  // d energy / d circumcentre
};

class Evaluator {
 public:
  // Points [0, ns) are fixed, [ns, ne) move; the cells of both count. Points from ne on
  // (ghosts) only close the cells of the others.
  Evaluator(std::size_t ns, std::size_t ne, const std::vector<Frame>& frame,
            const std::vector<double>& size, int p)
      : ns_(ns),
        ne_(ne),
        frame_(frame),
        size_(size),
        p_(p),
        coef_(6.0 / ((p + 1.0) * (p + 2.0) * (p + 3.0))) {}

  double operator()(const std::vector<Vec3>& x, std::vector<Vec3>* grad) {
    std::vector<std::pair<K::Point_3, std::int32_t>> pts(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      pts[i] = {K::Point_3(x[i][0], x[i][1], x[i][2]), static_cast<std::int32_t>(i)};
    Delaunay dt(pts.begin(), pts.end());
    // Cells: numbered, with their circumcentres and inverse systems.
    std::vector<CellGeometry> cells;
    std::vector<Eigen::Matrix3d> binvs;
    for (auto c = dt.all_cells_begin(); c != dt.all_cells_end(); ++c) c->info() = -1;
    cells.reserve(dt.number_of_finite_cells());
    binvs.reserve(dt.number_of_finite_cells());
    for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
      CellGeometry g;
      Vec3 y[4];
      for (int a = 0; a < 4; ++a) {
        g.vertex[a] = c->vertex(a)->info();
        y[a] = x[g.vertex[a]];
      }
      Eigen::Matrix3d binv;
      if (!circumcentre(y, g.centre, binv)) {
        // Exact arithmetic for a sliver's centre: in doubles it may come out as NaN.
        using EK = CGAL::Exact_predicates_exact_constructions_kernel;
        EK::Point_3 e[4];
        for (int a = 0; a < 4; ++a) e[a] = EK::Point_3(y[a][0], y[a][1], y[a][2]);
        const EK::Point_3 cc = CGAL::circumcenter(e[0], e[1], e[2], e[3]);
        g.centre = {CGAL::to_double(cc.x()), CGAL::to_double(cc.y()), CGAL::to_double(cc.z())};
        binv.setZero();  // no derivative: a sliver
      }
      c->info() = static_cast<std::int32_t>(cells.size());
      cells.push_back(g);
      binvs.push_back(binv);
    }
    // Each counted point's edges (serial: CGAL marks cells while it collects them).
    std::vector<Delaunay::Vertex_handle> vh(x.size());
    for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v) vh[v->info()] = v;
    std::vector<std::size_t> first(ne_ + 1, 0);
    std::vector<Delaunay::Edge> edges;
    for (std::size_t i = 0; i < ne_; ++i) {
      // A point on top of another (a surface node repeated on a seam) is one vertex: the
      // vertex's cell is counted once, for the point it kept.
      if (vh[i] != Delaunay::Vertex_handle())
        dt.finite_incident_edges(vh[i], std::back_inserter(edges));
      first[i + 1] = edges.size();
    }
    std::vector<PointTerms> terms(ne_);
    const auto nne = static_cast<std::ptrdiff_t>(ne_);
#pragma omp parallel for schedule(dynamic, 64)
    for (std::ptrdiff_t i = 0; i < nne; ++i)
      point_terms(dt, x, cells, edges, first[i], first[i + 1], i, terms[i]);
    // Sums in point order: the same result for any number of threads.
    double energy = 0;
    for (const PointTerms& t : terms) energy += t.energy;
    if (grad) {
      grad->assign(ne_ - ns_, {0, 0, 0});
      std::vector<Vec3> g_cell(cells.size(), {0, 0, 0});
      for (std::size_t i = 0; i < ne_; ++i) {
        if (i >= ns_) (*grad)[i - ns_] = terms[i].grad;
        for (const auto& [c, g] : terms[i].by_cell)
          for (int d = 0; d < 3; ++d) g_cell[c][d] += g[d];
      }
      // dc/dx_a = B^-1 e_a (x_a - c)^T (a = 1..3), dc/dx_0 = B^-1 1 (c - x_0)^T.
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const Vec3& g = g_cell[c];
        if (g[0] == 0 && g[1] == 0 && g[2] == 0) continue;
        const Eigen::Vector3d w = binvs[c].transpose() * Eigen::Vector3d(g[0], g[1], g[2]);
        const CellGeometry& cg = cells[c];
        for (int a = 0; a < 4; ++a) {
          const std::int32_t v = cg.vertex[a];
          if (static_cast<std::size_t>(v) < ns_ || static_cast<std::size_t>(v) >= ne_) continue;
          const double s = a == 0 ? w[0] + w[1] + w[2] : w[a - 1];
          for (int d = 0; d < 3; ++d)
            (*grad)[v - ns_][d] += s * (a == 0 ? cg.centre[d] - x[v][d] : x[v][d] - cg.centre[d]);
        }
      }
    }
    return energy;
  }

 private:
  void point_terms(const Delaunay& dt, const std::vector<Vec3>& x,
                   const std::vector<CellGeometry>& cells, const std::vector<Delaunay::Edge>& edges,
                   std::size_t from, std::size_t to, std::size_t i, PointTerms& out) const {
    const Vec3& xi = x[i];
    const Frame& f = frame_[i];
    if (!(size_[i] > 0)) return;  // a surface node no triangle uses
    const double inv_h = 1.0 / size_[i];
    std::vector<std::int32_t> ring;
    auto add_cell = [&](std::int32_t c, const Vec3& g) {
      for (auto& [cc, gg] : out.by_cell)
        if (cc == c) {
          for (int d = 0; d < 3; ++d) gg[d] += g[d];
          return;
        }
      out.by_cell.push_back({c, g});
    };
    for (std::size_t e = from; e < to; ++e) {
      ring.clear();
      auto circ = dt.incident_cells(edges[e]);
      const auto start = circ;
      do {
        const std::int32_t c = circ->info();
        if (c < 0) {
          out = PointTerms{};  // on the convex hull: an unbounded cell, left out
          return;
        }
        ring.push_back(c);
        ++circ;
      } while (circ != start);
      if (ring.size() < 3) continue;
      // The facet dual to the edge: a convex polygon of circumcentres in ring order, as a fan
      // of tets with x_i; the orientation of the ring is fixed by the facet's total volume.
      const Vec3 c0 = v3::sub(cells[ring[0]].centre, xi);
      double total = 0;
      for (std::size_t k = 1; k + 1 < ring.size(); ++k)
        total += v3::dot(c0, v3::cross(v3::sub(cells[ring[k]].centre, xi),
                                       v3::sub(cells[ring[k + 1]].centre, xi)));
      const double sign = total < 0 ? -1.0 : 1.0;
      for (std::size_t k = 1; k + 1 < ring.size(); ++k) {
        const Vec3 d[3] = {c0, v3::sub(cells[ring[k]].centre, xi),
                           v3::sub(cells[ring[k + 1]].centre, xi)};
        const Vec3 n[3] = {v3::cross(d[1], d[2]), v3::cross(d[2], d[0]), v3::cross(d[0], d[1])};
        const double vol = sign * v3::dot(d[0], n[0]) / 6.0;
        // U[a][k]: the Voronoi vertex a in the frame, in sizes.
        double u[3][3];
        for (int a = 0; a < 3; ++a)
          for (int k3 = 0; k3 < 3; ++k3) u[a][k3] = v3::dot(f[k3], d[a]) * inv_h;
        double s = 0;
        double ds[3][3];  // d S / d U[a][k]
        for (int k3 = 0; k3 < 3; ++k3) {
          double v4[4] = {u[0][k3], u[1][k3], u[2][k3], 0};
          s += complete_h(p_, v4, 3);
          for (int a = 0; a < 3; ++a) {
            v4[3] = u[a][k3];
            ds[a][k3] = complete_h(p_ - 1, v4, 4);
          }
        }
        out.energy += coef_ * vol * s;
        for (int a = 0; a < 3; ++a) {
          Vec3 g;
          for (int dd = 0; dd < 3; ++dd) {
            g[dd] = coef_ * (s * sign * n[a][dd] / 6.0 +
                             vol * inv_h *
                                 (ds[a][0] * f[0][dd] + ds[a][1] * f[1][dd] + ds[a][2] * f[2][dd]));
            out.grad[dd] -= g[dd];
          }
          add_cell(ring[a == 0 ? 0 : k + a - 1], g);
        }
      }
    }
  }

  std::size_t ns_, ne_;
  const std::vector<Frame>& frame_;
  const std::vector<double>& size_;
  int p_;
  double coef_;
};

double norm_sq(const std::vector<Vec3>& v) {
  double s = 0;
  for (const Vec3& a : v) s += v3::dot(a, a);
  return s;
}

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += v3::dot(a[i], b[i]);
  return s;
}

}  // namespace

double lp_cvt_energy(const std::vector<Vec3>& all, std::size_t ns, std::size_t ni,
                     const std::vector<Frame>& frame, const std::vector<double>& size, int p,
                     std::vector<Vec3>* gradient) {
  Evaluator eval(ns, ns + ni, frame, size, p);
  return eval(all, gradient);
}

std::vector<Vec3> optimize_lp_cvt(const std::vector<Vec3>& all, std::size_t ns, std::size_t ni,
                                  const std::vector<Frame>& frame, const std::vector<double>& size,
                                  const LpCvtOptions& options, LpCvtReport* report) {
  if (options.p < 2 || options.p > 14 || options.p % 2)
    throw Error("Lp-CVT: p must be even, from 2 to 14, got " + std::to_string(options.p));
  std::vector<Vec3> x = all;
  const auto moving = [&](const std::vector<Vec3>& y) {
    return std::vector<Vec3>(y.begin() + ns, y.begin() + ns + ni);
  };
  if (options.iterations <= 0 || ni == 0) return moving(all);
  Evaluator eval(ns, ns + ni, frame, size, options.p);
  std::vector<Vec3> g, g_new, dir(ni), x_new;
  double e = eval(x, &g);
  LpCvtReport rep;
  rep.energy_before = e;
  rep.evaluations = 1;
  // L-BFGS (two-loop recursion, memory 7) with a backtracking line search. The first step moves
  // the farthest point by a tenth of the mean size.
  double mean_h = 0;
  for (std::size_t i = 0; i < ni; ++i) mean_h += size[ns + i];
  mean_h /= static_cast<double>(ni);
  constexpr std::size_t kMemory = 7;
  std::deque<std::pair<std::vector<Vec3>, std::vector<Vec3>>> mem;  // (s, y)
  for (int it = 0; it < options.iterations; ++it) {
    // dir = -H g
    std::vector<Vec3> q = g;
    std::vector<double> alpha(mem.size());
    for (std::size_t m = mem.size(); m-- > 0;) {
      const double rho = 1.0 / dot(mem[m].second, mem[m].first);
      alpha[m] = rho * dot(mem[m].first, q);
      for (std::size_t i = 0; i < ni; ++i)
        for (int d = 0; d < 3; ++d) q[i][d] -= alpha[m] * mem[m].second[i][d];
    }
    double gamma;
    if (mem.empty()) {
      double gmax = 0;
      for (const Vec3& a : g) gmax = std::max(gmax, v3::norm(a));
      gamma = gmax > 0 ? 0.1 * mean_h / gmax : 0;
    } else {
      gamma = dot(mem.back().first, mem.back().second) / norm_sq(mem.back().second);
    }
    for (std::size_t i = 0; i < ni; ++i)
      for (int d = 0; d < 3; ++d) q[i][d] *= gamma;
    for (std::size_t m = 0; m < mem.size(); ++m) {
      const double rho = 1.0 / dot(mem[m].second, mem[m].first);
      const double beta = rho * dot(mem[m].second, q);
      for (std::size_t i = 0; i < ni; ++i)
        for (int d = 0; d < 3; ++d) q[i][d] += (alpha[m] - beta) * mem[m].first[i][d];
    }
    for (std::size_t i = 0; i < ni; ++i)
      for (int d = 0; d < 3; ++d) dir[i][d] = -q[i][d];
    double slope = dot(g, dir);
    if (!(slope < 0)) {  // not a descent direction: restart from the gradient
      mem.clear();
      double gmax = 0;
      for (const Vec3& a : g) gmax = std::max(gmax, v3::norm(a));
      if (gmax == 0) break;
      for (std::size_t i = 0; i < ni; ++i)
        for (int d = 0; d < 3; ++d) dir[i][d] = -0.1 * mean_h / gmax * g[i][d];
      slope = dot(g, dir);
    }
    double step = 1;
    bool accepted = false;
    double e_new = e;
    for (int tries = 0; tries < 8; ++tries, step *= 0.5) {
      x_new = x;
      for (std::size_t i = 0; i < ni; ++i)
        for (int d = 0; d < 3; ++d) x_new[ns + i][d] += step * dir[i][d];
      e_new = eval(x_new, &g_new);
      ++rep.evaluations;
      if (e_new <= e + 1e-4 * step * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    std::vector<Vec3> s(ni), y(ni);
    for (std::size_t i = 0; i < ni; ++i)
      for (int d = 0; d < 3; ++d) {
        s[i][d] = x_new[ns + i][d] - x[ns + i][d];
        y[i][d] = g_new[i][d] - g[i][d];
      }
    if (dot(s, y) > 0) {
      mem.emplace_back(std::move(s), std::move(y));
      if (mem.size() > kMemory) mem.pop_front();
    }
    std::swap(x, x_new);
    std::swap(g, g_new);
    e = e_new;
    ++rep.iterations;
  }
  rep.energy_after = e;
  if (report) *report = rep;
  return moving(x);
}

}  // namespace hexfem
