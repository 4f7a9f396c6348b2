// Closest points on the part's geometry, for the nodes of curved (order-2) elements.
#pragma once

#include <optional>

#include "mesher/cad/cad_model.hpp"

namespace hexfem {

// The point of the geometry nearest p where a mesh edge between CAD faces f1 and f2 lies: on
// face f1's surface when f1 == f2, else on the CAD edge the two faces share (the nearest one if
// they share several). Empty when the projection fails or the faces share no edge.
std::optional<Vec3> closest_point_on_geometry(const CadModel& cad, const Vec3& p, int f1, int f2);

}  // namespace hexfem
