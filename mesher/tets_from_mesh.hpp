// Tets made elsewhere (another mesher's tet mesh, read from a file) as the recombination's input:
// the TetMesh and the SurfaceMesh of its boundary, in the form tetrahedralize() gives them
// (surface nodes first, tets positive, boundary triangles outward), so that recombine_tets()
// runs the paper's recombination on them as it does on TetGen's.
//
// Takes: a MixedMesh of first-order tets with its boundary triangles, tagged by surface entity
// (the CAD face ids); several volumes may share faces.
// Gives: TetsFromMesh, or a one-line hexfem::Error naming what is missing or wrong.
#pragma once

#include <cstddef>

#include "mesher/mesh/mixed_mesh.hpp"
#include "mesher/surface_mesh.hpp"
#include "mesher/tetrahedralize.hpp"

namespace hexfem {

struct TetsFromMesh {
  SurfaceMesh surface;
  TetMesh tets;
  std::size_t unused_nodes = 0;  // nodes of the file no tet holds (left out)
  std::size_t turned_tets = 0;   // tets given inside out, turned
};

// Every boundary face of the tets (a face of one tet, or between tets of two volumes) must be
// one of the mesh's boundary triangles, and every boundary triangle such a face.
TetsFromMesh tets_from_mesh(const MixedMesh& mesh);

}  // namespace hexfem
