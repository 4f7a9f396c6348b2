// Pyramid with the rational basis: base (±1,±1,0), apex (0,0,1),
// N_i = (1+ξ_iξ-ζ)(1+η_iη-ζ)/(4(1-ζ)) for the base corners, N_4 = ζ. Bilinear on the base (matches
// a hex face), linear on the triangles (matches a tet face).
#include "fem/element.hpp"

namespace hexfem {

void pyramid5_shape(const Vec3& xi, ShapeValues& s) {
  static constexpr double kCorner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  const double z = xi[2];
  const double d = 4 * (1 - z);
  s.n = 5;
  for (int i = 0; i < 4; ++i) {
    const double a = 1 + kCorner[i][0] * xi[0] - z;
    const double b = 1 + kCorner[i][1] * xi[1] - z;
    s.N[i] = a * b / d;
    s.dN[i][0] = kCorner[i][0] * b / d;
    s.dN[i][1] = kCorner[i][1] * a / d;
    s.dN[i][2] = (a * b / (1 - z) - a - b) / d;
  }
  s.N[4] = z;
  s.dN[4][0] = 0;
  s.dN[4][1] = 0;
  s.dN[4][2] = 1;
}

// Collapsed 2x2 Gauss-Legendre x 2-point Gauss-Jacobi(2,0): exact stiffness and mass on an affine
// pyramid; all points are interior, the apex (0/0) is never evaluated.
QuadRule pyramid5_rule() {
  return pyramid_rule(2);
}

}  // namespace hexfem
