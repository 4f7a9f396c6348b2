// Last volume stage: slivers left among free tets (a flat tet between two diagonal splits of a
// near-planar quad, not on an element's face and not mergeable into a pyramid) are removed by
// edge-removal flips (Shewchuk, "Two discrete optimization algorithms for the topological
// improvement of tetrahedral meshes", 2002): the n tets around an edge of the sliver are replaced
// by the 2(n-2) tets joining the edge's ends to a triangulation of the ring of vertices around
// it, the triangulation with the best min scaled Jacobian. Only free tets (in no element) are
// touched, and the shell's outer faces stay, so elements, NC faces and the surface are unchanged;
// the volume is the same up to rounding.
//
// Takes: the RecombineState (free tets) or the assembled MixedMesh.
// Gives: flipped slivers (SliverFlips), lifted vertices.
// Keeps: elements, surface and NC faces unchanged; no cell made worse than the recombination
// bounds.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "mesher/recombine_state.hpp"
#include "mesher/solid_locator.hpp"

namespace hexfem {

struct SliverFlips {
  std::vector<std::int32_t> removed;               // TetGen tets replaced (marked used)
  std::vector<std::array<std::int32_t, 4>> added;  // the tets replacing them, positive
  std::vector<std::int32_t> added_solid;
  std::size_t flips = 0;
  std::size_t slivers_left = 0;  // free tets still below flat_sj
};

// A flat tet lying on the surface (four coplanar surface vertices, e.g. a rectangle on a
// cylinder or a plane, whose two surface triangles split it along one diagonal while TetGen's
// tets inside use the other) holds no volume: it is dropped and the surface takes its two other
// faces (the same plane, the other diagonal, same CAD face and orientation). Done right after
// TetGen, so the recombination never sees it. Tets with min scaled Jacobian below flat_sj
// whose two surface faces meet on the diagonal (outward normals alike) and whose two other
// faces are inside qualify, unless the other diagonal is already a surface edge. Returns how many
// were dropped; `tets` and `surface` are updated.
std::size_t drop_flat_boundary_tets(TetMesh& tets, SurfaceMesh& surface, double flat_sj);

// Per CAD face id: 1 when the face bounds two solids (an interface of glued solids, --glue).
std::vector<char> interface_faces(const SurfaceMesh& surface);

// A flat tet on a face between two glued solids (two faces on it, four corners in its plane; or
// one face on it and one on an outer face in the same plane) lies between those triangles and its
// own solid's tets, which use the quad's other diagonal; the surface cannot take that diagonal,
// since the other solid's tets hold this one. When the
// two tets across its inner faces share their fourth vertex b, the three are the pyramid (quad,
// b) and become its two tets along the interface's diagonal (a 3-2 flip); else, when the other
// solid's two tets on the interface triangles share theirs, those two take T's inner diagonal
// (a 2-2 flip) and so does the interface. New tets must be better than flat_sj. Returns how
// many flat tets went; `tets` and `surface` are updated.
std::size_t flip_flat_interface_tets(TetMesh& tets, SurfaceMesh& surface, double flat_sj);

// Flips away every free tet with min scaled Jacobian below s.limits.sliver_quality whose edge
// shells are free and can be re-triangulated with a better minimum (shells of up to 7 tets).
// The tets replaced are marked used (s.verify(flips.removed) holds after). Deterministic.
SliverFlips flip_slivers(RecombineState& s);

// Last resort for slivers left after the flips (their shells are not free, or no flip helps):
// for each cell with a min scaled Jacobian below `below`, one of its interior vertices (index >=
// num_fixed_nodes; the surface nodes come first and stay on the CAD) is moved a little, to the
// trial position (steps of 2 to 20 % of the cell's mean edge, along the axes and the normals of
// the cell's corners) that most raises the worst cell at that vertex. A hex or prism there stays
// at or above min(its own, 0.3), a pyramid min(its own, 0.05): the recombination's bounds.
// Returns how many cells were improved.
std::size_t lift_slivers(MixedMesh& mesh, std::size_t num_fixed_nodes, double below);

// For each flat tet left in a finished mesh (min scaled Jacobian below
// kDegenerateScaledJacobian), typically four co-planar surface nodes that neither the flips nor
// the lift can change (four co-planar surface points: a rectangle of two rows of a cylinder's
// points, a trapezoid between a hole's wall and its floor at the same two angles), a point off its
// plane, inside the solid: from its centroid towards the farthest corner of the cells on its faces,
// 0.3 of the way. With that point among the interior points the tetrahedralization has no such tet
// there.
std::vector<Vec3> points_beside_flat_tets(const MixedMesh& mesh, const SolidLocator& locator);

}  // namespace hexfem
