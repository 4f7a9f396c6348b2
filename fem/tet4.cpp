// Linear tetrahedron.
#include "fem/element.hpp"

namespace hexfem {

void tet4_shape(const Vec3& xi, ShapeValues& s) {
  s.n = 4;
  s.N[0] = 1 - xi[0] - xi[1] - xi[2];
  s.N[1] = xi[0];
  s.N[2] = xi[1];
  s.N[3] = xi[2];
  for (int i = 0; i < 4; ++i)
    for (int d = 0; d < 3; ++d) s.dN[i][d] = i == 0 ? -1.0 : (i == d + 1 ? 1.0 : 0.0);
}

// Degree 2: the consistent mass (quadratic) exactly; the stiffness is constant.
QuadRule tet4_rule() {
  return tet_rule(0);
}

}  // namespace hexfem
