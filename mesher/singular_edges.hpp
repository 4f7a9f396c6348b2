// Stage 1 of the surface mesher, an input of the size field: the CAD edges where a solid's
// elastic fields are singular, so that a modal solve can mesh them finer (a priori grading).
// Two kinds: re-entrant edges (the solid's interior angle above 180 degrees: stresses grow like
// r^(lambda - 1), lambda about 0.54 at 270 degrees), and the rim of a clamped region (where a
// fixed face meets a free one: the same kind of singularity). Uniform meshes converge there at
// order 2 lambda whatever the element order; graded towards them, the rest of the part keeps
// the element's own order (validation/order2.md, "Graded towards the singular edges").
//
// Takes: the CAD model. Gives: edge ids (1-based, sorted, unique).
#pragma once

#include <vector>

#include "mesher/cad/cad_model.hpp"

namespace hexfem {

// Edges between two faces of one solid whose interior angle exceeds 180 + min_turn_deg degrees,
// at three points along the edge (a fillet's tangent edge, at 180, is not one).
std::vector<int> reentrant_edges(const CadModel& cad, double min_turn_deg = 10.0);

// Edges of the given faces that also bound a face outside the set: the rim of a region.
std::vector<int> rim_edges(const CadModel& cad, const std::vector<int>& faces);

}  // namespace hexfem
