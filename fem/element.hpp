// Isoparametric solid elements: shape functions per family (hex8.cpp, wedge6.cpp, pyramid5.cpp,
// tet4.cpp, in the reference cells of quadrature.hpp, Gmsh node order) and the generic
// integration of stiffness and consistent mass (element.cpp).
#pragma once

#include <array>
#include <vector>

#include "fem/material.hpp"
#include "fem/quadrature.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Shape functions and their derivatives with respect to the reference coordinates.
struct ShapeValues {
  int n = 0;
  double N[kMaxCellNodes];
  double dN[kMaxCellNodes][3];
};

void hex8_shape(const Vec3& xi, ShapeValues& s);
void wedge6_shape(const Vec3& xi, ShapeValues& s);
void pyramid5_shape(const Vec3& xi, ShapeValues& s);  // rational; undefined at the apex
void tet4_shape(const Vec3& xi, ShapeValues& s);
void shape_functions(CellKind kind, const Vec3& xi, ShapeValues& s);

// The production rule of each family, exact for stiffness and consistent mass on undistorted
// (affine; for the hex, parallelepiped) elements:
//   hex8 2x2x2 Gauss (= CalculiX C3D8), wedge6 3-point triangle x 2-point Gauss,
//   pyramid5 collapsed 2x2 Gauss-Legendre x 2-point Gauss-Jacobi(2,0), tet4 4-point degree 2.
QuadRule hex8_rule();
QuadRule wedge6_rule();
QuadRule pyramid5_rule();
QuadRule tet4_rule();
QuadRule default_rule(CellKind kind);

// Shape values tabulated at a rule's points.
struct ReferenceElement {
  CellKind kind{};
  int n = 0;
  std::vector<ShapeValues> shape;
  std::vector<double> weight;
};
ReferenceElement tabulate(CellKind kind, const QuadRule& rule);
// The production rule tabulated once per kind.
const ReferenceElement& reference_element(CellKind kind);

// Element stiffness K (3n x 3n, row-major, DOF 3*i+a) and the scalar consistent mass
// m (n x n, m_ij = ∫ rho N_i N_j; the 3n x 3n mass is m ⊗ I3). Returns the smallest Jacobian
// determinant over the quadrature points (<= 0: the element is inverted or degenerate).
double element_matrices(const ReferenceElement& ref, const Vec3* x, const Material& mat, double* K,
                        double* m);

// Strains (xx, yy, zz, 2xy, 2yz, 2zx) at each quadrature point for nodal displacements
// u (3n, DOF 3*i+a).
std::vector<std::array<double, 6>> element_strains(const ReferenceElement& ref, const Vec3* x,
                                                   const double* u);

}  // namespace hexfem
