// The hand-over between the surface mesher (issue 4) and the volume mesher (issue 5).
#pragma once

#include <array>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct SurfaceMesh {
  // nodes + boundary triangles (bface_nodes, 4th slot -1) tagged by CAD face id in
  // bface_cad_face; no cells. Triangles are oriented with outward normals. All solids of the
  // part are in one mesh; solid_of_face maps a CAD face id to the solid(s) it bounds.
  MixedMesh mesh;
  // Per node: the cross-field frame (d1, d2, n), unit vectors, n the outward surface normal.
  std::vector<std::array<Vec3, 3>> frame;
  // Per node: the target element size there (the size field at the node).
  std::vector<double> size;
  // Per node: true when the node lies on a CAD edge or vertex (not interior to a face).
  std::vector<bool> on_edge;
  // For each solid id (index = solid id; entry 0 unused): the CAD face ids bounding it.
  std::vector<std::vector<int>> faces_of_solid;
};

}  // namespace hexfem
