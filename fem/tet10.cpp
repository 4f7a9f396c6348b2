// Quadratic tetrahedron (tet10): corners λ(2λ-1), mid-edge nodes 4 λ_a λ_b, with the barycentric
// coordinates λ = (1-ξ-η-ζ, ξ, η, ζ) and Gmsh's edge order.
#include "fem/element.hpp"
#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

void tet10_shape(const Vec3& xi, ShapeValues& s) {
  const double L[4] = {1 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]};
  static constexpr double dL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  s.n = 10;
  for (int i = 0; i < 4; ++i) {
    s.N[i] = L[i] * (2 * L[i] - 1);
    for (int d = 0; d < 3; ++d) s.dN[i][d] = (4 * L[i] - 1) * dL[i][d];
  }
  const auto& edges = edges_of(CellKind::Tet4);
  for (int e = 0; e < 6; ++e) {
    const int a = edges[e][0], b = edges[e][1];
    s.N[4 + e] = 4 * L[a] * L[b];
    for (int d = 0; d < 3; ++d) s.dN[4 + e][d] = 4 * (dL[a][d] * L[b] + L[a] * dL[b][d]);
  }
}

// Collapsed 3x3x3 (degree 5): the mass integrand N_i N_j has degree 4 on an affine tet, the
// stiffness degree 2. (CalculiX C3D10 integrates the stiffness with 4 points, exact as well.)
QuadRule tet10_rule() {
  return tet_rule(3);
}

}  // namespace hexfem
