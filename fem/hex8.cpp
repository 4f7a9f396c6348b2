// Trilinear hexahedron on [-1,1]^3.
#include "fem/element.hpp"

namespace hexfem {

void hex8_shape(const Vec3& xi, ShapeValues& s) {
  static constexpr double kCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                           {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  s.n = 8;
  for (int i = 0; i < 8; ++i) {
    const double a = 1 + kCorner[i][0] * xi[0];
    const double b = 1 + kCorner[i][1] * xi[1];
    const double c = 1 + kCorner[i][2] * xi[2];
    s.N[i] = a * b * c / 8;
    s.dN[i][0] = kCorner[i][0] * b * c / 8;
    s.dN[i][1] = kCorner[i][1] * a * c / 8;
    s.dN[i][2] = kCorner[i][2] * a * b / 8;
  }
}

// Same rule as CalculiX C3D8, so the two codes agree to round-off on the same mesh.
QuadRule hex8_rule() {
  return hex_rule(2);
}

}  // namespace hexfem
