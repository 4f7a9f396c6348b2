// Stage 4: the packing of parallelograms (paper, "Surface meshing"). From the edge points, a
// FIFO front: each point spawns four candidates at ±h d1, ±h d2 (first guess through the
// metric tensor, eq. 2, then moved along that parametric direction until the 3D distance is
// h); a candidate is kept when it is inside the trimmed face and no existing point lies within
// k h of it in the L∞ distance oriented by the candidate's frame (eq. 7). Spatial search:
// a Boost.Geometry R-tree queried with the axis-aligned box of the exclusion parallelogram.
//
// Takes: a face's FaceField and boundary points.
// Gives: the face's interior points (FacePoints).
// Keeps: no two points within k h in the frame's L-infinity distance; points inside the trimmed
// face.
#pragma once

#include <cstddef>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/cross_field.hpp"
#include "mesher/edge_points.hpp"

namespace hexfem {

struct PackingOptions {
  double k = 0.7;           // exclusion square half-side, in units of h
  std::size_t budget = 0;   // most points this face may get (0 = unbounded)
  std::vector<Vec2> seeds;  // points placed before the fronts run (opposite_seeds), if free
};

// Interior points of one face, in the order they were inserted.
struct FacePoints {
  std::vector<Vec2> uv;
  std::vector<Vec3> xyz;
  std::size_t candidates = 0;  // candidates examined
};

// Throws hexfem::Error when the face needs more points than options.budget.
FacePoints pack_face(const CadModel& cad, const FaceField& field, const FaceBoundary& boundary,
                     const EdgePoints& points, const PackingOptions& options);

// A thin wall's two sides packed alike (--align-opposite T, a study switch): points of faces
// packed earlier that lie across the wall from `field`'s face become its seeds. A candidate p
// qualifies when its nearest point q on the face (searched from c.start) is inside the trimmed
// face, between 0.3 and T local sizes away, with the two outward normals opposite (within
// 25 deg) and p on the solid's side of the face along the normal. Returns the q's parameters,
// each moved h/20 along the face's frame (see the .cpp), in the candidates' order.
struct SeedCandidate {
  int face = 0;      // the face p was packed on
  Vec3 p{};          // the point
  Vec2 source_uv{};  // its parameters there
  Vec2 start{};      // parameters of the face's own point nearest p
};
std::vector<Vec2> opposite_seeds(const CadModel& cad, const FaceField& field,
                                 const std::vector<SeedCandidate>& candidates,
                                 double max_thickness);

}  // namespace hexfem
