#include "mesher/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
double det3(const Vec3& a, const Vec3& b, const Vec3& c) {
  return dot(a, cross(b, c));
}

// Scale that makes the ideal shape of each kind score 1 (hexes keep the paper's eq. 8).
double ideal_scale(CellKind kind) {
  switch (kind) {
    case CellKind::Tet4:
      return std::sqrt(2.0);
    case CellKind::Pyramid5:
      return std::sqrt(2.0);
    case CellKind::Wedge6:
      return 2.0 / std::sqrt(3.0);
    case CellKind::Hex8:
      return 1.0;
  }
  return 1.0;
}

void gather(const MixedMesh& mesh, std::size_t c, Vec3* x) {
  const std::int32_t* ids = mesh.cell(c);
  for (int i = 0; i < num_nodes(mesh.cell_kind[c]); ++i) x[i] = mesh.nodes[ids[i]];
}

// Trilinear hex: det J integrated by 2x2x2 Gauss, exact (det J has degree <= 2 per variable).
double hex_volume(const Vec3* x) {
  const double g = 1.0 / std::sqrt(3.0);
  static const int sx[8] = {-1, 1, 1, -1, -1, 1, 1, -1};
  static const int sy[8] = {-1, -1, 1, 1, -1, -1, 1, 1};
  static const int sz[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
  double vol = 0.0;
  for (int q = 0; q < 8; ++q) {
    const double r = g * sx[q], s = g * sy[q], t = g * sz[q];
    Vec3 jr{}, js{}, jt{};
    for (int i = 0; i < 8; ++i) {
      const double dr = 0.125 * sx[i] * (1 + s * sy[i]) * (1 + t * sz[i]);
      const double ds = 0.125 * sy[i] * (1 + r * sx[i]) * (1 + t * sz[i]);
      const double dt = 0.125 * sz[i] * (1 + r * sx[i]) * (1 + s * sy[i]);
      for (int d = 0; d < 3; ++d) {
        jr[d] += dr * x[i][d];
        js[d] += ds * x[i][d];
        jt[d] += dt * x[i][d];
      }
    }
    vol += det3(jr, js, jt);  // weight 1 per point; reference cube volume 8 -> factor 1
  }
  return vol;
}

// Wedge: triangle (r,s) x line t in [-1,1]; det J is linear in (r,s), quadratic in t:
// the centroid rule times 2-point Gauss is exact.
double wedge_volume(const Vec3* x) {
  const double g = 1.0 / std::sqrt(3.0);
  double vol = 0.0;
  for (double t : {-g, g}) {
    const double r = 1.0 / 3.0, s = 1.0 / 3.0;
    const double lo = 0.5 * (1 - t), hi = 0.5 * (1 + t);
    Vec3 jr{}, js{}, jt{};
    for (int d = 0; d < 3; ++d) {
      jr[d] = lo * (x[1][d] - x[0][d]) + hi * (x[4][d] - x[3][d]);
      js[d] = lo * (x[2][d] - x[0][d]) + hi * (x[5][d] - x[3][d]);
      const double bot = (1 - r - s) * x[0][d] + r * x[1][d] + s * x[2][d];
      const double top = (1 - r - s) * x[3][d] + r * x[4][d] + s * x[5][d];
      jt[d] = 0.5 * (top - bot);
    }
    vol += 0.5 * det3(jr, js, jt);  // triangle area 1/2, Gauss weight 1
  }
  return vol;
}

// Pyramid under the rational map: the cone from the apex over the bilinear base,
// V = (1/3) ∫∫ (X - apex) . (X_u x X_v) du dv, degree <= 2 per variable: 2x2 Gauss is exact.
double pyramid_volume(const Vec3* x) {
  const double g = 1.0 / std::sqrt(3.0);
  double vol = 0.0;
  for (double u : {-g, g}) {
    for (double v : {-g, g}) {
      const double n0 = 0.25 * (1 - u) * (1 - v), n1 = 0.25 * (1 + u) * (1 - v);
      const double n2 = 0.25 * (1 + u) * (1 + v), n3 = 0.25 * (1 - u) * (1 + v);
      Vec3 p{}, xu{}, xv{};
      for (int d = 0; d < 3; ++d) {
        p[d] = n0 * x[0][d] + n1 * x[1][d] + n2 * x[2][d] + n3 * x[3][d] - x[4][d];
        xu[d] = 0.25 * ((1 - v) * (x[1][d] - x[0][d]) + (1 + v) * (x[2][d] - x[3][d]));
        xv[d] = 0.25 * ((1 - u) * (x[3][d] - x[0][d]) + (1 + u) * (x[2][d] - x[1][d]));
      }
      // Base (0,1,2,3) is counter-clockwise seen from the apex, so X_u x X_v points to the apex
      // and (X - apex) away from it: the sign is negative for a positive pyramid.
      vol -= dot(p, cross(xu, xv)) / 3.0;
    }
  }
  return vol;
}

double tet_volume(const Vec3* x) {
  return det3(sub(x[1], x[0]), sub(x[2], x[0]), sub(x[3], x[0])) / 6.0;
}

}  // namespace

double volume(CellKind kind, const Vec3* x) {
  switch (kind) {
    case CellKind::Tet4:
      return tet_volume(x);
    case CellKind::Pyramid5:
      return pyramid_volume(x);
    case CellKind::Wedge6:
      return wedge_volume(x);
    case CellKind::Hex8:
      return hex_volume(x);
  }
  return 0.0;
}

double min_scaled_jacobian(CellKind kind, const Vec3* x) {
  const CornerEdges ce = corners_of(kind);
  double worst = std::numeric_limits<double>::max();
  for (int k = 0; k < ce.count; ++k) {
    const auto& c = ce.corner[k];
    const Vec3 e1 = sub(x[c[1]], x[c[0]]), e2 = sub(x[c[2]], x[c[0]]), e3 = sub(x[c[3]], x[c[0]]);
    const double len = norm(e1) * norm(e2) * norm(e3);
    const double sj = len > 0 ? det3(e1, e2, e3) / len : 0.0;
    worst = std::min(worst, sj);
  }
  return worst * ideal_scale(kind);
}

double cell_volume(const MixedMesh& mesh, std::size_t c) {
  Vec3 x[kMaxCellNodes];
  gather(mesh, c, x);
  return volume(mesh.cell_kind[c], x);
}

double cell_min_scaled_jacobian(const MixedMesh& mesh, std::size_t c) {
  Vec3 x[kMaxCellNodes];
  gather(mesh, c, x);
  return min_scaled_jacobian(mesh.cell_kind[c], x);
}

bool cell_is_inverted(const MixedMesh& mesh, std::size_t c) {
  Vec3 x[kMaxCellNodes] = {};  // (slots past the kind's corners are never read)
  gather(mesh, c, x);
  return is_inverted(mesh.cell_kind[c], x);
}

bool is_inverted(CellKind kind, const Vec3* x) {
  const CornerEdges ce = corners_of(kind);
  for (int k = 0; k < ce.count; ++k) {
    const auto& cn = ce.corner[k];
    if (det3(sub(x[cn[1]], x[cn[0]]), sub(x[cn[2]], x[cn[0]]), sub(x[cn[3]], x[cn[0]])) <= 0)
      return true;
  }
  return false;
}

bool cell_is_degenerate(const MixedMesh& mesh, std::size_t c) {
  return !cell_is_inverted(mesh, c) &&
         cell_min_scaled_jacobian(mesh, c) < kDegenerateScaledJacobian;
}

}  // namespace hexfem
