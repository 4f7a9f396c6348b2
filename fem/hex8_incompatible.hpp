// Hex8 with incompatible (bubble) modes, condensed: a bending-accurate alternative to the fully
// integrated trilinear hex (which locks in bending, like CalculiX C3D8).
#pragma once

#include "fem/element.hpp"

namespace hexfem {

// 24x24 stiffness (row-major, DOF 3*i+a, Gmsh node order). The consistent mass is the
// trilinear element's (element_matrices). Returns the smallest Jacobian determinant at the
// Gauss points (<= 0: inverted or degenerate element).
double hex8_incompatible_stiffness(const Vec3* x, const Material& mat, double* K);

}  // namespace hexfem
