// Structured meshes of a box [0,Lx]x[0,Ly]x[0,Lz], for tests and validation everywhere.
#pragma once

#include <functional>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// nx*ny*nz cubes (cells of the lattice), each filled according to `kind`:
//   Hex8     one hexahedron;
//   Tet4     six tetrahedra around the cube diagonal (0,0,0)-(1,1,1) (Kuhn subdivision: every
//            cube is split the same way, so shared faces are triangulated identically);
//   Wedge6   two prisms, the bottom square split along its (0,0)-(1,1) diagonal, extruded in z;
//   Pyramid5 a pyramid + tet mix: a node at the cube centre, six pyramids on the cube faces,
//            the two pyramids on the faces normal to x each split into two tets along the face's
//            (y0,z0)-(y1,z1) diagonal (4 pyramids + 4 tets per cube, conforming).
// Nodes of the lattice come first, numbered i + (nx+1)*(j + (ny+1)*k); cube-centre nodes follow.
// Every cell is positively oriented (Gmsh ordering). Boundary faces (the cells' own faces,
// outward) are tagged with CAD-face ids 1..6 = x=0, x=Lx, y=0, y=Ly, z=0, z=Lz; solid id 1.
// Throws hexfem::Error for a non-positive length or count.
MixedMesh make_box_mesh(Vec3 lengths, int nx, int ny, int nz, CellKind kind);

// The same lattice with a fill chosen per cube (i, j, k), for hand-made mixed meshes:
//   Hex, Tets (Kuhn, as above), Wedges (as above),
//   Pyramids: a cube-centre node and six pyramids, the faces in `split_faces` (bit f for face
//   f = -x, +x, -y, +y, -z, +z) replaced by two tets each along the face's lowest-highest corner
//   diagonal (the Kuhn diagonal, so a split face matches a Tets neighbour).
// Conformity between neighbours is the caller's business: a Hex next to Tets leaves
// non-conformal quad faces, which is what a test of those wants.
enum class CubeFill { Hex, Tets, Wedges, Pyramids };
struct CubeSpec {
  CubeFill fill = CubeFill::Hex;
  unsigned split_faces = 0;
};
MixedMesh make_box_mesh(Vec3 lengths, int nx, int ny, int nz,
                        const std::function<CubeSpec(int i, int j, int k)>& spec);

}  // namespace hexfem
