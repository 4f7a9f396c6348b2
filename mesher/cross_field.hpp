// Stage 3: the surface cross field and the face size field (paper, "Cross fields", eq. 3-4).
// On a background triangulation of each face's parameter plane (CGAL's 2D Delaunay mesher,
// constrained by the edge points), three Laplace problems share one matrix: cos 4θ and sin 4θ
// with Dirichlet data from the boundary tangents, and the size with the edge sizes. θ is the
// angle of d1 from s1 = t1/|t1| in the tangent plane.
//
// Takes: a face, its boundary points and their sizes.
// Gives: a FaceField: frame and size at any (u, v) of the face.
// Keeps: unit cross directions in the tangent plane; sizes at most the face bound.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "mesher/cad/cad_model.hpp"
#include "mesher/edge_points.hpp"
#include "mesher/size_field.hpp"

namespace hexfem {

// The frame of the field at a point of a face, with the surface data it was built from.
struct Frame {
  Vec3 p{}, t1{}, t2{};  // point and parametric derivatives
  Vec3 d1{}, d2{}, n{};  // n = t1 x t2 normalised (parameter-plane orientation, not outward)
  double h = 0;          // size field
  bool ok = false;       // false at a singular point where no tangent plane is defined
};

class FaceField {
 public:
  FaceField(const CadModel& cad, int f, const FaceBoundary& boundary, const EdgePoints& points,
            const SizeField& size);
  ~FaceField();
  FaceField(FaceField&&) noexcept;
  FaceField& operator=(FaceField&&) noexcept;

  int face() const { return face_; }
  Frame frame(Vec2 uv) const;
  double size(Vec2 uv) const;
  // Mean |t1|, |t2| over the face: scaling u and v by these makes the parameter plane close
  // to isometric (exactly so for planes and cylinders).
  Vec2 scale() const { return scale_; }
  std::size_t background_triangles() const;

 private:
  struct Data;
  const CadModel* cad_;
  int face_;
  Vec2 scale_{1, 1};
  std::unique_ptr<Data> data_;
  // (cos 4θ, sin 4θ, h) interpolated at uv.
  std::array<double, 3> interpolate(Vec2 uv) const;
};

}  // namespace hexfem
