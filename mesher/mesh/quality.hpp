// Element measures: exact volumes and corner scaled Jacobians (paper eq. 8).
#pragma once

#include <cstddef>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Exact volume of cell c: the hex and wedge as their trilinear / bilinear-linear maps (a
// non-planar quad face is the ruled surface of those maps), the pyramid as the rational map
// (two tets over the base diagonals averaged, exact for its bilinear base), the tet as a tet.
double cell_volume(const MixedMesh& mesh, std::size_t c);

// Minimum over the corners of det(e1,e2,e3)/(|e1||e2||e3|) with e_i the three edges at the
// corner (paper eq. 8, signed). For hexes this is the paper's Q; tets, wedges and pyramids are
// scaled so that their ideal shape (regular tet, equilateral right prism, pyramid with all edges
// equal) scores 1. The pyramid apex is not a trihedral corner and is not sampled.
double cell_min_scaled_jacobian(const MixedMesh& mesh, std::size_t c);

// True when some corner has a Jacobian determinant <= 0 (the cell is inverted or flat).
bool cell_is_inverted(const MixedMesh& mesh, std::size_t c);

// A cell that is not inverted but so flat (min scaled Jacobian below this) that its stiffness
// is ~1/volume and ruins the conditioning of K: a solver must refuse it like an inverted one.
inline constexpr double kDegenerateScaledJacobian = 1e-6;

// True when the cell is not inverted and its min scaled Jacobian is below
// kDegenerateScaledJacobian.
bool cell_is_degenerate(const MixedMesh& mesh, std::size_t c);

// Same measures from raw corner coordinates (kind's Gmsh ordering), for candidate elements
// that are not in a mesh yet (the recombination scores its hexes this way).
double min_scaled_jacobian(CellKind kind, const Vec3* corners);
double volume(CellKind kind, const Vec3* corners);
bool is_inverted(CellKind kind, const Vec3* corners);

}  // namespace hexfem
