// Serendipity hexahedron (hex20) on [-1,1]^3: corners
// (1+ξ_iξ)(1+η_iη)(1+ζ_iζ)(ξ_iξ+η_iη+ζ_iζ-2)/8, mid-edge nodes (1-t²)(1+a u)(1+b v)/4 with t the
// coordinate along the edge; Gmsh's edge order.
#include "fem/element.hpp"
#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

namespace {
constexpr double kCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
}  // namespace

void hex20_shape(const Vec3& xi, ShapeValues& s) {
  s.n = 20;
  for (int i = 0; i < 8; ++i) {
    double f[3], g[3];  // f[d] = 1 + c_d x_d, g[d] = c_d
    for (int d = 0; d < 3; ++d) {
      f[d] = 1 + kCorner[i][d] * xi[d];
      g[d] = kCorner[i][d];
    }
    const double sum = g[0] * xi[0] + g[1] * xi[1] + g[2] * xi[2] - 2;
    const double prod = f[0] * f[1] * f[2];
    s.N[i] = prod * sum / 8;
    for (int d = 0; d < 3; ++d) {
      const double others = f[(d + 1) % 3] * f[(d + 2) % 3];  // not prod / f[d]: 0/0 on a face
      s.dN[i][d] = (g[d] * others * sum + prod * g[d]) / 8;
    }
  }
  const auto& edges = edges_of(CellKind::Hex8);
  for (int e = 0; e < 12; ++e) {
    const int i = 8 + e;
    double c[3];  // the node's reference coordinates; the edge direction has c = 0
    int t = 0;
    for (int d = 0; d < 3; ++d) {
      c[d] = (kCorner[edges[e][0]][d] + kCorner[edges[e][1]][d]) / 2;
      if (c[d] == 0) t = d;
    }
    const int u = (t + 1) % 3, v = (t + 2) % 3;
    const double bt = 1 - xi[t] * xi[t], fu = 1 + c[u] * xi[u], fv = 1 + c[v] * xi[v];
    s.N[i] = bt * fu * fv / 4;
    s.dN[i][t] = -2 * xi[t] * fu * fv / 4;
    s.dN[i][u] = bt * c[u] * fv / 4;
    s.dN[i][v] = bt * fu * c[v] / 4;
  }
}

// 3x3x3 Gauss, as CalculiX C3D20: exact stiffness and mass on a parallelepiped.
QuadRule hex20_rule() {
  return hex_rule(3);
}

}  // namespace hexfem
