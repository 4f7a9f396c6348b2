// Certified lower bounds of det J over a whole curved cell, where det J is a polynomial: its
// Bernstein coefficients bound it from below (the convex-hull property), as Johnen, Remacle and
// Geuzaine (2013) do for Gmsh's validity check. Samples alone can miss a fold between them.
//   tet10: det J is a cubic on the tetrahedron (20 Bernstein coefficients);
//   hex20 (serendipity): its degree is at most 5 in each reference coordinate (216).
// The coefficients come from det J at as many points (Bernstein interpolation).
#pragma once

#include <optional>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct JacobianBound {
  double lower;    // <= det J everywhere in the cell
  double max_det;  // largest det J at the interpolation points
};

// The bound for an order-2 tet or hex cell whose nodes (corners, then mid-edge nodes) are at
// x; nullopt for the other kinds (wedge15: not done; pyramid13: rational, no polynomial).
std::optional<JacobianBound> order2_jacobian_bound(CellKind kind, const Vec3* x);

}  // namespace hexfem
