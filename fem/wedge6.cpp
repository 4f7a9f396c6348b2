// Linear wedge (prism): linear triangle x linear segment; triangle at ζ = -1 (nodes 0-2) and
// ζ = +1 (nodes 3-5).
#include "fem/element.hpp"

namespace hexfem {

void wedge6_shape(const Vec3& xi, ShapeValues& s) {
  const double L[3] = {1 - xi[0] - xi[1], xi[0], xi[1]};
  static constexpr double dL[3][2] = {{-1, -1}, {1, 0}, {0, 1}};
  s.n = 6;
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) {
      const int i = a + 3 * side;
      const double h = side == 0 ? (1 - xi[2]) / 2 : (1 + xi[2]) / 2;
      const double dh = side == 0 ? -0.5 : 0.5;
      s.N[i] = L[a] * h;
      s.dN[i][0] = dL[a][0] * h;
      s.dN[i][1] = dL[a][1] * h;
      s.dN[i][2] = L[a] * dh;
    }
}

// 3 points x 2: the mass integrand is quadratic in the triangle and in ζ, which this integrates
// exactly on a right prism (CalculiX's C3D6 uses a single triangle point and is not exact).
QuadRule wedge6_rule() {
  return wedge_rule(2);
}

}  // namespace hexfem
