#include "mesher/cross_field.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "mesher/cdt_domain.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/rtree2d.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
struct VInfo {
  int index = -1;  // index into the FaceBoundary points, -1 for a point the mesher added
};
using Vbi = CGAL::Triangulation_vertex_base_with_info_2<VInfo, K>;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<K, Vbi>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<
    int, K, CGAL::Constrained_Delaunay_triangulation_face_base_2<K>>;
using Fb = CGAL::Delaunay_mesh_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<CDT>;

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using BPoint = rt2::Point;
using BBox = rt2::Box;
using Tree = rt2::BoxTree;
using P3 = bg::model::point<double, 3, bg::cs::cartesian>;
using P3Tree = bgi::rtree<std::pair<P3, int>, bgi::rstar<16>>;
constexpr double kGradation = 0.5;  // as for the edge points (edge_points.cpp)
using v3::cross;
using v3::dot;
using v3::norm;
using v3::scaled;

// (cos 4θ, sin 4θ) of a tangent direction T relative to s1 = t1/|t1| at the surface point.
std::array<double, 2> cross_of(const Vec3& T, const SurfaceDerivs& d) {
  const Vec3 n = cross(d.du, d.dv);
  const double l1 = norm(d.du), ln = norm(n);
  if (l1 < 1e-300 || ln < 1e-300) return {0, 0};
  const Vec3 s1 = scaled(d.du, 1 / l1);
  const Vec3 s2 = cross(scaled(n, 1 / ln), s1);
  const double th = std::atan2(dot(T, s2), dot(T, s1));
  return {std::cos(4 * th), std::sin(4 * th)};
}

}  // namespace

struct FaceField::Data {
  std::vector<Vec2> uv;
  std::vector<std::array<int, 3>> tris;
  std::vector<std::array<double, 3>> value;  // cos 4θ, sin 4θ, h per background vertex
  Tree tree;
  // Boundary points finer than the rest of the face: the size inside grows from them by at
  // most kGradation per unit length (the Laplace solution alone would leave a coarse point
  // facing a refined stretch of boundary).
  std::vector<std::pair<P3, double>> fine;
  P3Tree fine_tree;
  double fine_min = 0;
};

FaceField::~FaceField() = default;
FaceField::FaceField(FaceField&&) noexcept = default;
FaceField& FaceField::operator=(FaceField&&) noexcept = default;

std::size_t FaceField::background_triangles() const {
  return data_->tris.size();
}

namespace {

// Mean |t1|, |t2| over a 9 x 9 grid of samples of face f's parameter box.
Vec2 metric_scale(const CadModel& cad, int f) {
  const auto bounds = cad.uv_bounds(f);
  double su = 0, sv = 0;
  int nu = 0, nv = 0;
  for (int i = 0; i < 9; ++i) {
    for (int j = 0; j < 9; ++j) {
      const Vec2 uv{bounds[0] + (bounds[1] - bounds[0]) * (i + 0.5) / 9,
                    bounds[2] + (bounds[3] - bounds[2]) * (j + 0.5) / 9};
      const SurfaceDerivs d = cad.eval(f, uv);
      const double a = norm(d.du), c = norm(d.dv);
      if (a > 0 && std::isfinite(a)) su += a, ++nu;
      if (c > 0 && std::isfinite(c)) sv += c, ++nv;
    }
  }
  return {nu > 0 ? su / nu : 1.0, nv > 0 ? sv / nv : 1.0};
}

// Boundary data: which boundary points carry Dirichlet values (a usable edge tangent), and the
// values (cos 4θ, sin 4θ, h); every point carries its edge size.
struct BoundaryValues {
  std::vector<bool> dirichlet;
  std::vector<std::array<double, 3>> value;
  double hmean = 0, hmax = 0;
};
BoundaryValues boundary_values(const CadModel& cad, int f, const FaceBoundary& b,
                               const EdgePoints& points, const SizeField& size) {
  const auto& ces = cad.coedges(f);
  const std::size_t nb = b.uv.size();
  auto usable = [&](int c) {
    const CoEdge& ce = ces[static_cast<std::size_t>(c)];
    return !ce.seam && !cad.edge_degenerate(ce.edge);
  };
  BoundaryValues bv{std::vector<bool>(nb, false),
                    std::vector<std::array<double, 3>>(nb, {1, 0, size.global()})};
  for (std::size_t i = 0; i < nb; ++i) {
    const double h = points.size[static_cast<std::size_t>(b.node[i])];
    std::array<double, 2> z{0, 0};
    int uses = 0;
    const SurfaceDerivs d = cad.eval(f, b.uv[i]);
    if (usable(b.coedge[i])) {
      const int e = ces[static_cast<std::size_t>(b.coedge[i])].edge;
      const auto zi = cross_of(cad.edge_derivative(e, b.t[i]), d);
      z = {zi[0], zi[1]};
      ++uses;
    }
    if (b.prev_coedge[i] >= 0 && usable(b.prev_coedge[i])) {
      // A corner: the other edge's tangent at its end, averaged with this one's.
      const CoEdge& pc = ces[static_cast<std::size_t>(b.prev_coedge[i])];
      const Vec2 r = cad.edge_range(pc.edge);
      const auto zi = cross_of(cad.edge_derivative(pc.edge, pc.reversed ? r[0] : r[1]), d);
      if (uses == 0 || z[0] * zi[0] + z[1] * zi[1] > -0.5) {
        z = {z[0] + zi[0], z[1] + zi[1]};
        ++uses;
      }
    }
    const double len = std::hypot(z[0], z[1]);
    if (uses > 0 && len > 1e-6) {
      bv.dirichlet[i] = true;
      bv.value[i] = {z[0] / len, z[1] / len, h};
    } else {
      bv.value[i][2] = h;
    }
  }
  double hsum = 0;
  for (std::size_t i = 0; i < nb; ++i) hsum += bv.value[i][2];
  bv.hmean = nb > 0 ? hsum / static_cast<double>(nb) : size.global();
  for (std::size_t i = 0; i < nb; ++i) bv.hmax = std::max(bv.hmax, bv.value[i][2]);
  return bv;
}

// Background triangulation of the face's domain, in the scaled parameter plane: the boundary
// points, refined to about bg_size.
void triangulate_background(CDT& cdt, int f, const FaceBoundary& b, Vec2 scale, double bg_size) {
  std::vector<CDT::Vertex_handle> handles(b.uv.size());
  for (std::size_t i = 0; i < b.uv.size(); ++i) {
    handles[i] = cdt.insert(CDT::Point(b.uv[i][0] * scale[0], b.uv[i][1] * scale[1]));
    if (handles[i]->info().index < 0) handles[i]->info().index = static_cast<int>(i);
  }
  for (const auto& seg : b.segments) {
    auto va = handles[static_cast<std::size_t>(seg[0])],
         vb = handles[static_cast<std::size_t>(seg[1])];
    if (va != vb) cdt.insert_constraint(va, vb);
  }
  if (cdt.dimension() < 2)
    throw Error("face " + std::to_string(f) + ": its boundary is flat in the parameter plane");
  // The boundary must not run over itself: no segment split by another boundary point or a
  // crossing, and no turn back along itself at a point (a sliver of no width). CGAL's
  // refinement is not to be trusted on such a domain (the fuzz, seed 97: a cylinder whose seam
  // line lies off its surface doubled back along its bottom circle in the parameter plane and
  // crashed it with a null neighbour).
  const std::string runs_over = "face " + std::to_string(f) +
                                ": its boundary runs over itself in the parameter plane; its edge "
                                "curves may not lie on the surface";
  std::vector<int> next(b.uv.size(), -1);
  for (const auto& seg : b.segments) {
    const auto va = handles[static_cast<std::size_t>(seg[0])],
               vb = handles[static_cast<std::size_t>(seg[1])];
    if (va == vb) continue;
    if (!cdt.is_edge(va, vb)) throw Error(runs_over);
    next[static_cast<std::size_t>(seg[0])] = seg[1];
  }
  auto at = [&](int i) { return b.uv[static_cast<std::size_t>(i)]; };
  for (const auto& seg : b.segments) {
    const int n = next[static_cast<std::size_t>(seg[1])];
    if (n < 0 || next[static_cast<std::size_t>(seg[0])] != seg[1]) continue;
    const Vec2 p = at(seg[0]), q = at(seg[1]), r = at(n);
    const double ax = (q[0] - p[0]) * scale[0], ay = (q[1] - p[1]) * scale[1];
    const double bx = (r[0] - q[0]) * scale[0], by = (r[1] - q[1]) * scale[1];
    const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
    if (la > 0 && lb > 0 && ax * bx + ay * by < -(1 - 1e-9) * la * lb) throw Error(runs_over);
  }
  mark_nesting_levels(cdt);
  for (auto fh = cdt.all_faces_begin(); fh != cdt.all_faces_end(); ++fh)
    fh->set_in_domain(!cdt.is_infinite(fh) && fh->info() % 2 == 1);
  // Refined a point at a time under a cap: on a malformed boundary (pcurves that cross or
  // nearly touch at a tiny angle) CGAL's refinement never ends. A sound face needs about its
  // area over bg_size^2 points plus a graded layer along its boundary; the cap is far above.
  double area = 0;
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh)
    if (fh->is_in_domain()) area += std::abs(cdt.triangle(fh).area());
  const double cap = 100.0 * (area / (bg_size * bg_size) + static_cast<double>(b.uv.size())) + 1e5;
  CGAL::Delaunay_mesher_2<CDT, Criteria> mesher(cdt, Criteria(0.125, bg_size));
  mesher.init(true);
  while (!mesher.is_refinement_done()) {
    mesher.step_by_step_refine_mesh();
    if (static_cast<double>(cdt.number_of_vertices()) > cap)
      throw Error("face " + std::to_string(f) +
                  ": its parameter plane could not be triangulated (the refinement passed " +
                  std::to_string(static_cast<long long>(cap)) +
                  " points); its boundary curves may not lie on the surface");
  }
}

// The background vertices (uv, triangles) and their unknowns: copies of one boundary node (the
// two sides of a seam, a pole line) share one.
struct Domain {
  std::vector<int> unknown;   // per vertex
  std::vector<int> boundary;  // per vertex: boundary point index or -1
  std::vector<bool> on_constraint;
  int num_unknowns = 0;
};
Domain extract_domain(const CDT& cdt, const FaceBoundary& b, Vec2 scale, std::vector<Vec2>& uv,
                      std::vector<std::array<int, 3>>& tris) {
  Domain dom;
  std::unordered_map<int, int> node_unknown;
  std::unordered_map<CDT::Vertex_handle, int> vid;
  auto vertex_id = [&](CDT::Vertex_handle v) {
    auto it = vid.find(v);
    if (it != vid.end()) return it->second;
    const int id = static_cast<int>(uv.size());
    vid.emplace(v, id);
    uv.push_back({v->point().x() / scale[0], v->point().y() / scale[1]});
    dom.boundary.push_back(v->info().index);
    dom.on_constraint.push_back(cdt.are_there_incident_constraints(v));
    int u = -1;
    if (v->info().index >= 0) {
      const int node = b.node[static_cast<std::size_t>(v->info().index)];
      auto [nit, inserted] = node_unknown.emplace(node, dom.num_unknowns);
      if (inserted) ++dom.num_unknowns;
      u = nit->second;
    } else {
      u = dom.num_unknowns++;
    }
    dom.unknown.push_back(u);
    return id;
  };
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
    if (!fh->is_in_domain()) continue;
    tris.push_back({vertex_id(fh->vertex(0)), vertex_id(fh->vertex(1)), vertex_id(fh->vertex(2))});
  }
  return dom;
}

// Dirichlet data per unknown; points the mesher put on a constraint take the values of the
// boundary segment under them.
struct Dirichlet {
  std::vector<int> fixed;
  std::vector<std::array<double, 3>> value;
};
Dirichlet dirichlet_data(const Domain& dom, const std::vector<Vec2>& uv, const FaceBoundary& b,
                         const BoundaryValues& bv, Vec2 scale, double bg_size) {
  const auto nunk = static_cast<std::size_t>(dom.num_unknowns);
  Dirichlet dd{std::vector<int>(nunk, 0), std::vector<std::array<double, 3>>(nunk, {0, 0, 0})};
  for (std::size_t v = 0; v < uv.size(); ++v) {
    const auto u = static_cast<std::size_t>(dom.unknown[v]);
    const int bi = dom.boundary[v];
    if (bi >= 0) {
      if (bv.dirichlet[static_cast<std::size_t>(bi)]) {
        dd.fixed[u] = 1;
        dd.value[u] = bv.value[static_cast<std::size_t>(bi)];
      }
      continue;
    }
    if (!dom.on_constraint[v]) continue;
    // A mesher point on a constraint: the boundary segment under it.
    const Vec2 p = uv[v];
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_s = 0;
    double best_w = 0;
    for (std::size_t k = 0; k < b.segments.size(); ++k) {
      const Vec2& a = b.uv[static_cast<std::size_t>(b.segments[k][0])];
      const Vec2& c = b.uv[static_cast<std::size_t>(b.segments[k][1])];
      const double ax = (c[0] - a[0]) * scale[0], ay = (c[1] - a[1]) * scale[1];
      const double px = (p[0] - a[0]) * scale[0], py = (p[1] - a[1]) * scale[1];
      const double l2 = ax * ax + ay * ay;
      const double w = l2 > 0 ? std::clamp((px * ax + py * ay) / l2, 0.0, 1.0) : 0.0;
      const double d = std::hypot(px - w * ax, py - w * ay);
      if (d < best) best = d, best_s = k, best_w = w;
    }
    if (b.segments.empty() || best > 1e-9 * bg_size) continue;
    const auto& seg = b.segments[best_s];
    const auto i0 = static_cast<std::size_t>(seg[0]), i1 = static_cast<std::size_t>(seg[1]);
    if (bv.dirichlet[i0] && bv.dirichlet[i1]) {
      dd.fixed[u] = 1;
      for (int k = 0; k < 3; ++k)
        dd.value[u][k] = (1 - best_w) * bv.value[i0][k] + best_w * bv.value[i1][k];
    }
  }
  return dd;
}

// P1 Laplace (cotangent weights in the scaled plane) for the three fields, Dirichlet rows
// eliminated; the value per unknown.
std::vector<std::array<double, 3>> solve_laplace(const std::vector<Vec2>& uv,
                                                 const std::vector<std::array<int, 3>>& tris,
                                                 const Domain& dom, const Dirichlet& dd, Vec2 scale,
                                                 double hmean) {
  const int nunk = dom.num_unknowns;
  std::vector<int> free_index(static_cast<std::size_t>(nunk), -1);
  int nfree = 0, nfixed = 0;
  for (int u = 0; u < nunk; ++u) {
    if (dd.fixed[static_cast<std::size_t>(u)])
      ++nfixed;
    else
      free_index[static_cast<std::size_t>(u)] = nfree++;
  }
  std::vector<std::array<double, 3>> result = dd.value;
  if (nfixed == 0) {
    // No boundary tangent anywhere (a sphere, a torus): a constant field along the
    // parametrisation, and the mean boundary size.
    for (auto& r : result) r = {1, 0, hmean};
    return result;
  }
  if (nfree == 0) return result;
  std::vector<Eigen::Triplet<double>> trips;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nfree, 3);
  for (const auto& t : tris) {
    std::array<std::array<double, 2>, 3> q;
    for (int k = 0; k < 3; ++k)
      q[k] = {uv[static_cast<std::size_t>(t[k])][0] * scale[0],
              uv[static_cast<std::size_t>(t[k])][1] * scale[1]};
    const double area2 =
        (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
    if (!(std::abs(area2) > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      // Cotangent of the angle at k, weight of edge (i, j).
      const double ex1 = q[i][0] - q[k][0], ey1 = q[i][1] - q[k][1];
      const double ex2 = q[j][0] - q[k][0], ey2 = q[j][1] - q[k][1];
      const double w = 0.5 * (ex1 * ex2 + ey1 * ey2) / std::abs(area2);
      const int ui = dom.unknown[static_cast<std::size_t>(t[i])];
      const int uj = dom.unknown[static_cast<std::size_t>(t[j])];
      if (ui == uj) continue;
      const int fi = free_index[static_cast<std::size_t>(ui)],
                fj = free_index[static_cast<std::size_t>(uj)];
      if (fi >= 0) trips.emplace_back(fi, fi, w);
      if (fj >= 0) trips.emplace_back(fj, fj, w);
      if (fi >= 0 && fj >= 0) {
        trips.emplace_back(fi, fj, -w);
        trips.emplace_back(fj, fi, -w);
      } else if (fi >= 0) {
        for (int c = 0; c < 3; ++c) rhs(fi, c) += w * dd.value[static_cast<std::size_t>(uj)][c];
      } else if (fj >= 0) {
        for (int c = 0; c < 3; ++c) rhs(fj, c) += w * dd.value[static_cast<std::size_t>(ui)][c];
      }
    }
  }
  // A tiny diagonal shift keeps unknowns cut off from every Dirichlet point solvable.
  for (int i = 0; i < nfree; ++i) trips.emplace_back(i, i, 1e-12);
  Eigen::SparseMatrix<double> A(nfree, nfree);
  A.setFromTriplets(trips.begin(), trips.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  Eigen::MatrixXd x;
  if (solver.info() == Eigen::Success) x = solver.solve(rhs);
  const bool solved = solver.info() == Eigen::Success && x.allFinite();
  for (int u = 0; u < nunk; ++u) {
    const int fi = free_index[static_cast<std::size_t>(u)];
    if (fi < 0) continue;
    if (solved)
      result[static_cast<std::size_t>(u)] = {x(fi, 0), x(fi, 1), x(fi, 2)};
    else
      result[static_cast<std::size_t>(u)] = {1, 0, hmean};
  }
  return result;
}

}  // namespace

FaceField::FaceField(const CadModel& cad, int f, const FaceBoundary& b, const EdgePoints& points,
                     const SizeField& size)
    : cad_(&cad), face_(f), data_(std::make_unique<Data>()) {
  scale_ = metric_scale(cad, f);
  const BoundaryValues bv = boundary_values(cad, f, b, points, size);
  // Coarser than the final mesh (the fields are smooth), capped at ~20k triangles per face.
  const double area = std::max(cad.face_area(f), 1e-300);
  const double bg_size = std::max(2.5 * bv.hmean, std::sqrt(area / 10000.0));
  CDT cdt;
  triangulate_background(cdt, f, b, scale_, bg_size);
  Data& D = *data_;
  const Domain dom = extract_domain(cdt, b, scale_, D.uv, D.tris);
  const Dirichlet dd = dirichlet_data(dom, D.uv, b, bv, scale_, bg_size);
  const auto result = solve_laplace(D.uv, D.tris, dom, dd, scale_, bv.hmean);
  D.value.resize(D.uv.size());
  for (std::size_t v = 0; v < D.uv.size(); ++v) {
    auto val = result[static_cast<std::size_t>(dom.unknown[v])];
    if (!(val[2] > 0)) val[2] = bv.hmean;
    val[2] = std::min(val[2], size.surface_bound(f, D.uv[v]));
    D.value[v] = val;
  }
  // Lookup of the background triangle at a point.
  std::vector<std::pair<BBox, int>> boxes;
  boxes.reserve(D.tris.size());
  for (std::size_t t = 0; t < D.tris.size(); ++t) {
    const auto& a = D.uv[static_cast<std::size_t>(D.tris[t][0])];
    const auto& c = D.uv[static_cast<std::size_t>(D.tris[t][1])];
    const auto& e = D.uv[static_cast<std::size_t>(D.tris[t][2])];
    boxes.emplace_back(BBox(BPoint(std::min({a[0], c[0], e[0]}), std::min({a[1], c[1], e[1]})),
                            BPoint(std::max({a[0], c[0], e[0]}), std::max({a[1], c[1], e[1]}))),
                       static_cast<int>(t));
  }
  D.tree = Tree(boxes.begin(), boxes.end());
  // The boundary points finer than the rest, for the gradation from them.
  std::vector<std::pair<P3, int>> fine_pts;
  D.fine_min = bv.hmax;
  for (std::size_t i = 0; i < b.uv.size(); ++i) {
    const double h = bv.value[i][2];
    if (h >= 0.9 * bv.hmax) continue;
    const Vec3& x = points.xyz[static_cast<std::size_t>(b.node[i])];
    fine_pts.emplace_back(P3(x[0], x[1], x[2]), static_cast<int>(D.fine.size()));
    D.fine.emplace_back(P3(x[0], x[1], x[2]), h);
    D.fine_min = std::min(D.fine_min, h);
  }
  D.fine_tree = P3Tree(fine_pts.begin(), fine_pts.end());
  if (D.tris.empty()) throw Error("face " + std::to_string(f) + ": empty parametric domain");
}

std::array<double, 3> FaceField::interpolate(Vec2 uv) const {
  const Data& D = *data_;
  auto bary = [&](int t, std::array<double, 3>& w) {
    const auto& a = D.uv[static_cast<std::size_t>(D.tris[static_cast<std::size_t>(t)][0])];
    const auto& b = D.uv[static_cast<std::size_t>(D.tris[static_cast<std::size_t>(t)][1])];
    const auto& c = D.uv[static_cast<std::size_t>(D.tris[static_cast<std::size_t>(t)][2])];
    const double det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (det == 0) {
      w = {1.0 / 3, 1.0 / 3, 1.0 / 3};
      return -1.0;
    }
    w[1] = ((uv[0] - a[0]) * (c[1] - a[1]) - (uv[1] - a[1]) * (c[0] - a[0])) / det;
    w[2] = ((b[0] - a[0]) * (uv[1] - a[1]) - (b[1] - a[1]) * (uv[0] - a[0])) / det;
    w[0] = 1 - w[1] - w[2];
    return std::min({w[0], w[1], w[2]});
  };
  int best = -1;
  double best_min = -std::numeric_limits<double>::infinity();
  std::array<double, 3> w{}, best_w{};
  auto consider = [&](int t) {
    const double m = bary(t, w);
    if (m > best_min) best_min = m, best = t, best_w = w;
  };
  for (auto it = D.tree.qbegin(bgi::intersects(BPoint(uv[0], uv[1]))); it != D.tree.qend(); ++it) {
    consider(it->second);
    if (best_min >= 0) break;
  }
  if (best < 0) {
    for (auto it = D.tree.qbegin(bgi::nearest(BPoint(uv[0], uv[1]), 4)); it != D.tree.qend(); ++it)
      consider(it->second);
  }
  if (best_min < 0) {
    double s = 0;
    for (double& x : best_w) s += (x = std::max(x, 0.0));
    for (double& x : best_w) x = s > 0 ? x / s : 1.0 / 3;
  }
  std::array<double, 3> out{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c)
      out[c] += best_w[k] *
                D.value[static_cast<std::size_t>(D.tris[static_cast<std::size_t>(best)][k])][c];
  return out;
}

double FaceField::size(Vec2 uv) const {
  return interpolate(uv)[2];
}

Frame FaceField::frame(Vec2 uv) const {
  Frame fr;
  const auto val = interpolate(uv);
  fr.h = val[2];
  SurfaceDerivs d = cad_->eval(face_, uv);
  fr.p = d.p;
  const Data& D = *data_;
  if (!D.fine.empty() && fr.h > D.fine_min) {
    const double r = (fr.h - D.fine_min) / kGradation;
    const auto& c = d.p;
    for (auto it = D.fine_tree.qbegin(bgi::intersects(bg::model::box<P3>(
             P3(c[0] - r, c[1] - r, c[2] - r), P3(c[0] + r, c[1] + r, c[2] + r))));
         it != D.fine_tree.qend(); ++it) {
      const auto& [q, h] = D.fine[static_cast<std::size_t>(it->second)];
      const double dx = q.get<0>() - c[0], dy = q.get<1>() - c[1], dz = q.get<2>() - c[2];
      fr.h = std::min(fr.h, h + kGradation * std::sqrt(dx * dx + dy * dy + dz * dz));
    }
  }
  fr.t1 = d.du;
  fr.t2 = d.dv;
  Vec3 n = cross(d.du, d.dv);
  const double l1 = norm(d.du), ln = norm(n);
  if (!(ln > 1e-14 * std::max(l1 * norm(d.dv), 1e-300)) || !(l1 > 0)) return fr;  // singular
  n = scaled(n, 1 / ln);
  const Vec3 s1 = scaled(d.du, 1 / l1);
  const Vec3 s2 = cross(n, s1);
  const double th = 0.25 * std::atan2(val[1], val[0]);
  const double c = std::cos(th), s = std::sin(th);
  fr.d1 = {s1[0] * c + s2[0] * s, s1[1] * c + s2[1] * s, s1[2] * c + s2[2] * s};
  fr.d2 = cross(n, fr.d1);
  fr.n = n;
  fr.ok = true;
  return fr;
}

}  // namespace hexfem
