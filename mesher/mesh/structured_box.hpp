// Structured meshes of a box [0,Lx]x[0,Ly]x[0,Lz], for tests and validation everywhere.
#pragma once

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

}  // namespace hexfem
