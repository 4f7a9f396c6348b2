// Isoparametric solid elements: shape functions per family (hex8.cpp, wedge6.cpp, pyramid5.cpp,
// tet4.cpp and at order 2 hex20.cpp, wedge15.cpp, pyramid13.cpp, tet10.cpp, in the reference
// cells of quadrature.hpp, Gmsh node order) and the generic integration of stiffness and
// consistent mass (element.cpp).
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
  double N[kMaxElementNodes];
  double dN[kMaxElementNodes][3];
};

void hex8_shape(const Vec3& xi, ShapeValues& s);
void wedge6_shape(const Vec3& xi, ShapeValues& s);
void pyramid5_shape(const Vec3& xi, ShapeValues& s);  // rational; undefined at the apex
void tet4_shape(const Vec3& xi, ShapeValues& s);
void shape_functions(CellKind kind, const Vec3& xi, ShapeValues& s);
// Order 2, Gmsh node order (corners, then the mid-edge nodes of element_topology.hpp's edges):
// hex20 serendipity, wedge15 serendipity, tet10 Lagrange, and pyramid13 with Bedrosian's (1992)
// rational basis (denominator 1-ζ; quad8 on the base, tri6 on the sides).
void hex20_shape(const Vec3& xi, ShapeValues& s);
void wedge15_shape(const Vec3& xi, ShapeValues& s);
void pyramid13_shape(const Vec3& xi, ShapeValues& s);  // undefined at the apex
void tet10_shape(const Vec3& xi, ShapeValues& s);
void shape_functions(CellKind kind, int order, const Vec3& xi, ShapeValues& s);

// The production rule of each family, exact for stiffness and consistent mass on undistorted
// (affine; for the hex, parallelepiped) elements:
//   hex8 2x2x2 Gauss (= CalculiX C3D8), wedge6 3-point triangle x 2-point Gauss,
//   pyramid5 collapsed 2x2 Gauss-Legendre x 2-point Gauss-Jacobi(2,0), tet4 4-point degree 2.
QuadRule hex8_rule();
QuadRule wedge6_rule();
QuadRule pyramid5_rule();
QuadRule tet4_rule();
QuadRule default_rule(CellKind kind);
// Order 2, exact for stiffness and consistent mass on affine elements (for the hex: a
// parallelepiped): hex20 3x3x3 Gauss (= CalculiX C3D20), wedge15 collapsed 3x3 triangle x 3-point
// Gauss (27 points, degree 5), pyramid13 collapsed 3x3 Gauss-Legendre x 3-point Gauss-Jacobi(2,0),
// tet10 collapsed 3x3x3 (degree 5; the mass integrand has degree 4).
QuadRule hex20_rule();
QuadRule wedge15_rule();
QuadRule pyramid13_rule();
QuadRule tet10_rule();
QuadRule default_rule(CellKind kind, int order);

// Shape values tabulated at a rule's points.
struct ReferenceElement {
  CellKind kind{};
  int order = 1;
  int n = 0;
  std::vector<ShapeValues> shape;
  std::vector<double> weight;
};
ReferenceElement tabulate(CellKind kind, const QuadRule& rule);
ReferenceElement tabulate(CellKind kind, int order, const QuadRule& rule);
// The production rule tabulated once per kind and order.
const ReferenceElement& reference_element(CellKind kind, int order = 1);

// Element stiffness K (3n x 3n, n <= kMaxElementNodes, row-major, DOF 3*i+a) and the scalar
// consistent mass m (n x n, m_ij = ∫ rho N_i N_j; the 3n x 3n mass is m ⊗ I3). Returns the smallest
// Jacobian determinant over the quadrature points (<= 0: the element is inverted or degenerate).
double element_matrices(const ReferenceElement& ref, const Vec3* x, const Material& mat, double* K,
                        double* m);

// Reference coordinates of the element's nodes (corners, then mid-edge nodes at order 2).
std::vector<Vec3> reference_nodes(CellKind kind, int order);

// det J at one point of a cell whose nodes (in the order of the shape functions) are at x.
double jacobian_determinant(const ShapeValues& s, const Vec3* x);

// Validity of cell c of the mesh at its order: min det J / max det J over the production rule's
// points and the nodes (the pyramid apex, where the rational basis is 0/0, replaced by the point
// at 0.99 of the axis). An order-2 cell whose ratio there is below kLatticeCheckBelow is also
// sampled on a lattice of 5 points per direction (125 in a hex), and a tet10 or hex20 must
// besides be proven valid by the lower bound of its Bernstein coefficients
// (fem/jacobian_bounds.hpp): if that bound is not positive, it is returned (over the largest det
// J). <= 0: inverted somewhere (or, for a tet10 or hex20, not proven valid).
inline constexpr double kLatticeCheckBelow = 0.2;
double element_jacobian_ratio(const MixedMesh& mesh, std::size_t c);
// The same over the production rule's points and the nodes only: a cheaper check for searches.
double element_jacobian_ratio_at_nodes_and_points(const MixedMesh& mesh, std::size_t c);

// The volume of cell c at the mesh's order (curved at order 2), and of all cells: det J over
// the production rule, as the mass matrix integrates it (exact for hex20 and tet10, whose det J
// the rules integrate exactly).
double element_volume(const MixedMesh& mesh, std::size_t c);
std::vector<double> element_volumes(const MixedMesh& mesh);  // of every cell, in cell order
double mesh_volume(const MixedMesh& mesh);

// Strains (xx, yy, zz, 2xy, 2yz, 2zx) at each quadrature point for nodal displacements
// u (3n, DOF 3*i+a).
std::vector<std::array<double, 6>> element_strains(const ReferenceElement& ref, const Vec3* x,
                                                   const double* u);

}  // namespace hexfem
