// Serendipity wedge (prism15): triangle at ζ = -1 (corners 0-2) and ζ = +1 (3-5), barycentric λ
// of the triangle, s = ±1 the corner's side. Corners λ(1+sζ)(2λ+sζ-2)/2, triangle mid-edge nodes
// 2λ_aλ_b(1+sζ), vertical mid-edge nodes λ(1-ζ²); Gmsh's edge order.
#include "fem/element.hpp"
#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

void wedge15_shape(const Vec3& xi, ShapeValues& s) {
  const double L[3] = {1 - xi[0] - xi[1], xi[0], xi[1]};
  static constexpr double dL[3][2] = {{-1, -1}, {1, 0}, {0, 1}};
  const double z = xi[2];
  s.n = 15;
  for (int i = 0; i < 6; ++i) {
    const int a = i % 3;
    const double sd = i < 3 ? -1.0 : 1.0;
    const double h = 1 + sd * z, q = 2 * L[a] + sd * z - 2;
    s.N[i] = L[a] * h * q / 2;
    for (int d = 0; d < 2; ++d) s.dN[i][d] = dL[a][d] * h * (q + 2 * L[a]) / 2;
    s.dN[i][2] = L[a] * sd * (q + h) / 2;
  }
  const auto& edges = edges_of(CellKind::Wedge6);
  for (int e = 0; e < 9; ++e) {
    const int i = 6 + e, p = edges[e][0], r = edges[e][1];
    if (p % 3 == r % 3) {  // vertical edge
      const int a = p % 3;
      s.N[i] = L[a] * (1 - z * z);
      for (int d = 0; d < 2; ++d) s.dN[i][d] = dL[a][d] * (1 - z * z);
      s.dN[i][2] = -2 * z * L[a];
    } else {
      const int a = p % 3, b = r % 3;
      const double sd = p < 3 ? -1.0 : 1.0, h = 1 + sd * z;
      s.N[i] = 2 * L[a] * L[b] * h;
      for (int d = 0; d < 2; ++d) s.dN[i][d] = 2 * (dL[a][d] * L[b] + L[a] * dL[b][d]) * h;
      s.dN[i][2] = 2 * L[a] * L[b] * sd;
    }
  }
}

// Collapsed 3x3 triangle (degree 5) x 3-point Gauss in ζ: the mass integrand has degree 4 in the
// triangle and in ζ on an affine prism, the stiffness as well. (CalculiX C3D15 uses 9 points.)
QuadRule wedge15_rule() {
  return wedge_rule(3, 3);
}

}  // namespace hexfem
