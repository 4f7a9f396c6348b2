// The serendipity quad8 face (corners, then the mid-edge nodes of edges (0,1), (1,2), (2,3),
// (3,0)) and the point of it nearest to a given point. Shared by the order-2 node placement
// (mesher/high_order_nodes) and the ties of hanging nodes (fem/nc_ties).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// Shape functions N[8] and their derivatives dN[8][2] at (x, y) in [-1, 1]^2.
void quad8_shape(double x, double y, double* N, double (*dN)[2]);

// The reference point (x, y) of the quad8 on `nodes` (8 node ids of mesh) nearest to p, by
// Gauss-Newton from the centre, clamped to [-1, 1]^2; w = N(x, y), and `at` the point itself.
struct Quad8Nearest {
  double x = 0, y = 0;
  double w[8] = {};
  Vec3 at{};
  double distance = 0;  // |at - p|
  double size = 0;      // the length of the diagonal from node 0 to node 2
};
Quad8Nearest quad8_nearest(const MixedMesh& mesh, const std::int32_t* nodes, const Vec3& p);

// The NC quad faces of an order-2 mesh as quad8s (corners in the face's order, then its
// mid-edge nodes), each with the mid-edge nodes of its two diagonals (0-2, 1-3): only the
// triangles across the face have one of them, the hanging node; -1 where no cell has the edge.
// Faces whose sides have no mid-edge node are left out.
struct NcQuad8 {
  std::array<std::int32_t, 8> nodes;
  std::array<std::int32_t, 2> diagonal;
};
std::vector<NcQuad8> nc_quad8_faces(const MixedMesh& mesh);

}  // namespace hexfem
