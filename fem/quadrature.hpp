// Quadrature rules on the reference elements (Gmsh reference cells):
//   hex      [-1,1]^3
//   wedge    triangle {ξ,η >= 0, ξ+η <= 1} x ζ in [-1,1]
//   pyramid  base (±1,±1,0), apex (0,0,1)
//   tet      {ξ,η,ζ >= 0, ξ+η+ζ <= 1}
// Weights include every Jacobian of the collapse maps, so Σw = reference volume.
#pragma once

#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct QuadPoint {
  Vec3 xi;
  double w;
};
using QuadRule = std::vector<QuadPoint>;

struct Rule1D {
  std::vector<double> x, w;
};

// n-point Gauss-Legendre on [-1,1] (exact to degree 2n-1).
Rule1D gauss_legendre(int n);
// n-point Gauss-Jacobi on [-1,1] for the weight (1-t)^alpha (1+t)^beta (Golub-Welsch).
Rule1D gauss_jacobi(int n, double alpha, double beta);

// n^3 tensor Gauss-Legendre.
QuadRule hex_rule(int n);
// The interior 3-point rule (degree 2) on the triangle, or with n > 0 a collapsed n x n
// Gauss rule (degree 2n-1) for reference checks.
QuadRule triangle_rule(int n = 0);
// Triangle rule x n-point Gauss in ζ.
QuadRule wedge_rule(int n_line, int n_triangle = 0);
// The 4-point degree-2 rule, or with n > 0 a collapsed n^3 rule (degree 2n-1).
QuadRule tet_rule(int n = 0);
// Collapsed coordinates ξ = r(1-ζ), η = s(1-ζ), ζ = (1+t)/2: n x n Gauss-Legendre in (r,s) x
// n-point Gauss-Jacobi (α=2, β=0) in t, which absorbs the (1-ζ)^2 of dV. Never samples the apex.
QuadRule pyramid_rule(int n);

}  // namespace hexfem
