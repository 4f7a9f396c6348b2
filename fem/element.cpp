#include "fem/element.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fem/jacobian_bounds.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

void shape_functions(CellKind kind, const Vec3& xi, ShapeValues& s) {
  switch (kind) {
    case CellKind::Hex8:
      hex8_shape(xi, s);
      return;
    case CellKind::Wedge6:
      wedge6_shape(xi, s);
      return;
    case CellKind::Pyramid5:
      pyramid5_shape(xi, s);
      return;
    case CellKind::Tet4:
      tet4_shape(xi, s);
      return;
  }
}

void shape_functions(CellKind kind, int order, const Vec3& xi, ShapeValues& s) {
  if (order != 2) return shape_functions(kind, xi, s);
  switch (kind) {
    case CellKind::Hex8:
      hex20_shape(xi, s);
      return;
    case CellKind::Wedge6:
      wedge15_shape(xi, s);
      return;
    case CellKind::Pyramid5:
      pyramid13_shape(xi, s);
      return;
    case CellKind::Tet4:
      tet10_shape(xi, s);
      return;
  }
}

QuadRule default_rule(CellKind kind, int order) {
  if (order != 2) return default_rule(kind);
  switch (kind) {
    case CellKind::Hex8:
      return hex20_rule();
    case CellKind::Wedge6:
      return wedge15_rule();
    case CellKind::Pyramid5:
      return pyramid13_rule();
    case CellKind::Tet4:
      return tet10_rule();
  }
  return {};
}

QuadRule default_rule(CellKind kind) {
  switch (kind) {
    case CellKind::Hex8:
      return hex8_rule();
    case CellKind::Wedge6:
      return wedge6_rule();
    case CellKind::Pyramid5:
      return pyramid5_rule();
    case CellKind::Tet4:
      return tet4_rule();
  }
  return {};
}

ReferenceElement tabulate(CellKind kind, const QuadRule& rule) {
  return tabulate(kind, 1, rule);
}

ReferenceElement tabulate(CellKind kind, int order, const QuadRule& rule) {
  ReferenceElement ref;
  ref.kind = kind;
  ref.order = order;
  ref.n = num_nodes(kind, order);
  for (const QuadPoint& p : rule) {
    ShapeValues s;
    shape_functions(kind, order, p.xi, s);
    ref.shape.push_back(s);
    ref.weight.push_back(p.w);
  }
  return ref;
}

const ReferenceElement& reference_element(CellKind kind, int order) {
  static const ReferenceElement table[kNumCellKinds] = {
      tabulate(CellKind::Tet4, tet4_rule()), tabulate(CellKind::Pyramid5, pyramid5_rule()),
      tabulate(CellKind::Wedge6, wedge6_rule()), tabulate(CellKind::Hex8, hex8_rule())};
  static const ReferenceElement table2[kNumCellKinds] = {
      tabulate(CellKind::Tet4, 2, tet10_rule()), tabulate(CellKind::Pyramid5, 2, pyramid13_rule()),
      tabulate(CellKind::Wedge6, 2, wedge15_rule()), tabulate(CellKind::Hex8, 2, hex20_rule())};
  return (order == 2 ? table2 : table)[static_cast<int>(kind)];
}

namespace {

// Physical gradients g[i] = dN_i/dx at one point; returns det J.
double physical_gradients(const ShapeValues& s, const Vec3* x, double g[][3]) {
  double J[3][3] = {};  // J[a][d] = dx_a / dξ_d
  for (int i = 0; i < s.n; ++i)
    for (int a = 0; a < 3; ++a)
      for (int d = 0; d < 3; ++d) J[a][d] += x[i][a] * s.dN[i][d];
  const double c00 = J[1][1] * J[2][2] - J[1][2] * J[2][1];
  const double c01 = J[1][2] * J[2][0] - J[1][0] * J[2][2];
  const double c02 = J[1][0] * J[2][1] - J[1][1] * J[2][0];
  const double det = J[0][0] * c00 + J[0][1] * c01 + J[0][2] * c02;
  if (!(det > 0)) return det;
  // inv(J)[d][a] = cofactor(a,d)/det; g_i[a] = Σ_d dN_i/dξ_d inv(J)[d][a].
  double inv[3][3];
  inv[0][0] = c00 / det;
  inv[1][0] = c01 / det;
  inv[2][0] = c02 / det;
  inv[0][1] = (J[0][2] * J[2][1] - J[0][1] * J[2][2]) / det;
  inv[1][1] = (J[0][0] * J[2][2] - J[0][2] * J[2][0]) / det;
  inv[2][1] = (J[0][1] * J[2][0] - J[0][0] * J[2][1]) / det;
  inv[0][2] = (J[0][1] * J[1][2] - J[0][2] * J[1][1]) / det;
  inv[1][2] = (J[0][2] * J[1][0] - J[0][0] * J[1][2]) / det;
  inv[2][2] = (J[0][0] * J[1][1] - J[0][1] * J[1][0]) / det;
  for (int i = 0; i < s.n; ++i)
    for (int a = 0; a < 3; ++a)
      g[i][a] = s.dN[i][0] * inv[0][a] + s.dN[i][1] * inv[1][a] + s.dN[i][2] * inv[2][a];
  return det;
}

}  // namespace

double element_matrices(const ReferenceElement& ref, const Vec3* x, const Material& mat, double* K,
                        double* m) {
  const int n = ref.n, nd = 3 * n;
  std::fill(K, K + nd * nd, 0.0);
  std::fill(m, m + n * n, 0.0);
  const double lambda = mat.lambda(), mu = mat.mu();
  double min_det = std::numeric_limits<double>::infinity();
  double g[kMaxElementNodes][3];
  for (std::size_t q = 0; q < ref.shape.size(); ++q) {
    const ShapeValues& s = ref.shape[q];
    const double det = physical_gradients(s, x, g);
    min_det = std::min(min_det, det);
    if (!(det > 0)) continue;  // the caller rejects the element
    const double w = ref.weight[q] * det;
    // (B_i^T D B_j)_ab = λ g_ia g_jb + μ g_ib g_ja + μ δ_ab g_i·g_j; upper blocks, mirrored below.
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) {
        const double dot = g[i][0] * g[j][0] + g[i][1] * g[j][1] + g[i][2] * g[j][2];
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b)
            K[(3 * i + a) * nd + 3 * j + b] +=
                w * (lambda * g[i][a] * g[j][b] + mu * g[i][b] * g[j][a] + (a == b ? mu * dot : 0));
        const double mij = w * mat.rho * s.N[i] * s.N[j];
        m[i * n + j] += mij;
      }
  }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) {
      m[i * n + j] = m[j * n + i];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          K[(3 * i + a) * nd + 3 * j + b] = K[(3 * j + b) * nd + 3 * i + a];
    }
  return min_det;
}

std::vector<Vec3> reference_nodes(CellKind kind, int order) {
  std::vector<Vec3> x;
  switch (kind) {
    case CellKind::Hex8:
      x = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
           {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
      break;
    case CellKind::Wedge6:
      x = {{0, 0, -1}, {1, 0, -1}, {0, 1, -1}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
      break;
    case CellKind::Pyramid5:
      x = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}};
      break;
    case CellKind::Tet4:
      x = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      break;
  }
  if (order == 2)
    for (int e = 0; e < num_edges(kind); ++e) {
      const Vec3 &a = x[edges_of(kind)[e][0]], &b = x[edges_of(kind)[e][1]];
      x.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
    }
  return x;
}

namespace {

// The production rule's points and the nodes of each kind and order, tabulated once.
const ReferenceElement& validity_samples(CellKind kind, int order) {
  static const auto make = [](CellKind k, int o) {
    QuadRule rule = default_rule(k, o);
    for (Vec3 p : reference_nodes(k, o)) {
      if (k == CellKind::Pyramid5 && p[2] == 1) p[2] = 0.99;
      rule.push_back({p, 1.0});
    }
    return tabulate(k, o, rule);
  };
  static const ReferenceElement table[2][kNumCellKinds] = {
      {make(CellKind::Tet4, 1), make(CellKind::Pyramid5, 1), make(CellKind::Wedge6, 1),
       make(CellKind::Hex8, 1)},
      {make(CellKind::Tet4, 2), make(CellKind::Pyramid5, 2), make(CellKind::Wedge6, 2),
       make(CellKind::Hex8, 2)}};
  return table[order == 2][static_cast<int>(kind)];
}

// A lattice of 5 points per direction over the order-2 reference cell (spacing a quarter of
// the cell, faces and edges included; the pyramid's top layer at 0.99 of the axis), tabulated once:
// between the production points a curved cell's det J can dip where they do not see it.
const ReferenceElement& lattice_samples(CellKind kind) {
  static const auto make = [](CellKind k) {
    QuadRule rule;
    for (int i = 0; i <= 4; ++i)
      for (int j = 0; j <= 4; ++j)
        for (int l = 0; l <= 4; ++l) {
          const double a = i / 4.0, b = j / 4.0, c = l / 4.0;
          switch (k) {
            case CellKind::Hex8:
              rule.push_back({{2 * a - 1, 2 * b - 1, 2 * c - 1}, 1.0});
              break;
            case CellKind::Wedge6:
              if (i + j <= 4) rule.push_back({{a, b, 2 * c - 1}, 1.0});
              break;
            case CellKind::Tet4:
              if (i + j + l <= 4) rule.push_back({{a, b, c}, 1.0});
              break;
            case CellKind::Pyramid5: {
              const double z = std::min(c, 0.99), w = 1 - z;
              rule.push_back({{w * (2 * a - 1), w * (2 * b - 1), z}, 1.0});
              break;
            }
          }
        }
    return tabulate(k, 2, rule);
  };
  static const ReferenceElement table[kNumCellKinds] = {
      make(CellKind::Tet4), make(CellKind::Pyramid5), make(CellKind::Wedge6), make(CellKind::Hex8)};
  return table[static_cast<int>(kind)];
}

// min and max of det J over the samples of `ref`, folded into lo and hi.
void jacobian_range(const ReferenceElement& ref, const Vec3* x, double& lo, double& hi) {
  for (const ShapeValues& s : ref.shape) {
    const double det = jacobian_determinant(s, x);
    if (!std::isfinite(det)) {  // a basis undefined there: never read as valid
      lo = -std::numeric_limits<double>::infinity();
      continue;
    }
    lo = std::min(lo, det);
    hi = std::max(hi, det);
  }
}

// The cell's node coordinates, in the order of its shape functions.
void cell_coordinates(const MixedMesh& mesh, std::size_t c, Vec3* x) {
  std::int32_t ids[kMaxElementNodes];
  const int n = mesh.element_nodes(c, ids);
  for (int i = 0; i < n; ++i) x[i] = mesh.nodes[ids[i]];
}

}  // namespace

double jacobian_determinant(const ShapeValues& s, const Vec3* x) {
  double J[3][3] = {};
  for (int i = 0; i < s.n; ++i)
    for (int a = 0; a < 3; ++a)
      for (int d = 0; d < 3; ++d) J[a][d] += x[i][a] * s.dN[i][d];
  return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
         J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
         J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

double element_jacobian_ratio(const MixedMesh& mesh, std::size_t c) {
  Vec3 x[kMaxElementNodes];
  cell_coordinates(mesh, c, x);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  jacobian_range(validity_samples(mesh.cell_kind[c], mesh.order), x, lo, hi);
  // Only a cell that is already far from affine there can dip below 0 between those points.
  if (mesh.order == 2 && !(hi > 0 && lo >= kLatticeCheckBelow * hi)) {
    const auto bound = order2_jacobian_bound(mesh.cell_kind[c], x);
    if (bound && !(bound->lower > 0)) {  // not proven positive: read as inverted
      lo = std::min(lo, bound->lower);
      hi = std::max(hi, bound->max_det);
    } else {  // proven positive (tet10, hex20) or not provable (wedge15, pyramid13): samples
      jacobian_range(lattice_samples(mesh.cell_kind[c]), x, lo, hi);
    }
  }
  return hi > 0 ? lo / hi : -1.0;
}

double element_jacobian_ratio_at_nodes_and_points(const MixedMesh& mesh, std::size_t c) {
  Vec3 x[kMaxElementNodes];
  cell_coordinates(mesh, c, x);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  jacobian_range(validity_samples(mesh.cell_kind[c], mesh.order), x, lo, hi);
  return hi > 0 ? lo / hi : -1.0;
}

double element_volume(const MixedMesh& mesh, std::size_t c) {
  Vec3 x[kMaxElementNodes];
  cell_coordinates(mesh, c, x);
  const ReferenceElement& ref = reference_element(mesh.cell_kind[c], mesh.order);
  double v = 0;
  for (std::size_t q = 0; q < ref.shape.size(); ++q)
    v += ref.weight[q] * jacobian_determinant(ref.shape[q], x);
  return v;
}

std::vector<double> element_volumes(const MixedMesh& mesh) {
  std::vector<double> v(mesh.num_cells());
  for (std::size_t c = 0; c < v.size(); ++c) v[c] = element_volume(mesh, c);
  return v;
}

double mesh_volume(const MixedMesh& mesh) {
  double v = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) v += element_volume(mesh, c);
  return v;
}

std::vector<std::array<double, 6>> element_strains(const ReferenceElement& ref, const Vec3* x,
                                                   const double* u) {
  std::vector<std::array<double, 6>> out;
  double g[kMaxElementNodes][3];
  for (const ShapeValues& s : ref.shape) {
    if (!(physical_gradients(s, x, g) > 0)) throw Error("element_strains: inverted element");
    double du[3][3] = {};  // du[a][b] = d u_a / d x_b
    for (int i = 0; i < s.n; ++i)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) du[a][b] += u[3 * i + a] * g[i][b];
    out.push_back({du[0][0], du[1][1], du[2][2], du[0][1] + du[1][0], du[1][2] + du[2][1],
                   du[2][0] + du[0][2]});
  }
  return out;
}

}  // namespace hexfem
