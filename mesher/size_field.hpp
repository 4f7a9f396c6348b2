// Stage 1 of the surface mesher: the size field. A global size h, optional sizes at CAD
// vertices and faces, and a curvature bound (N elements per 2*pi of turning). Vertex sizes spread
// along edges by 1D interpolation in arc length (paper, "Cross fields"); sizes from faces and from
// the curvature bound grow back from the vertex at kFaceSizeGrading instead; faces get theirs from
// a Laplace solve with the edge sizes as Dirichlet data (cross_field.cpp, same background mesh).
//
// Takes: the CAD model and SurfaceOptions (h, curvature, vertex sizes).
// Gives: a size at every point of every edge and a bound per face.
// Keeps: sizes in (0, h]; the same size on both sides of an edge.
#pragma once

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

#include "mesher/cad/cad_model.hpp"

namespace hexfem {

// The smallest size a user may ask for at a vertex, relative to the part's bounding-box diagonal.
inline constexpr double kMinRelativeSize = 1e-5;
// Growth of the size away from a sized face along an edge, per unit length: the rate at which the
// face interiors and the volume grow from a fine boundary (cross_field.cpp, frame_field_3d.hpp).
inline constexpr double kFaceSizeGrading = 0.3;

struct SizeOptions {
  double h = 1.0;                                    // global target size, mm
  int curvature = 0;                                 // elements per 2*pi; 0 = no curvature bound
  std::vector<std::pair<int, double>> vertex_sizes;  // (CAD vertex id, size)
  // (CAD face id, size): the face's edges take at most that size, so its interior (Laplace from
  // the edges) and the volume next to it do too; edges leaving the face grow from it by
  // kFaceSizeGrading per mm instead of spreading the fine size along their whole length.
  std::vector<std::pair<int, double>> face_sizes;
  // (CAD edge id, size): the edge takes at most that size, and everything around it grows from
  // it at kFaceSizeGrading (singular edges, singular_edges.hpp).
  std::vector<std::pair<int, double>> edge_sizes;
  // The curvature bound never goes below h * min_ratio (a tiny fillet radius would otherwise
  // ask for an unbounded number of points).
  double min_ratio = 0.05;
  // When larger than min_ratio: the curvature bound alone stops at h * curvature_min_ratio (the
  // default of modal and converge, which refine curved faces at most this much; min_ratio still
  // bounds the sizes for narrow faces).
  double curvature_min_ratio = 0;
};

class SizeField {
 public:
  // Throws hexfem::Error on h <= 0, a bad vertex, edge or face id or a size <= 0.
  SizeField(const CadModel& cad, const SizeOptions& options);

  double global() const { return h_; }
  double min_size() const { return h_min_; }
  // The smallest size any automatic bound (curvature, narrow faces) may ask for.
  double floor() const { return floor_; }
  double vertex_size(int v) const {
    const auto i = static_cast<std::size_t>(v - 1);
    return std::min(vertex_size_[i], graded_vertex_size_[i]);
  }
  // The size bound from a curvature kappa (infinite when the bound is off or kappa = 0).
  double curvature_bound(double kappa) const;
  // Size bound of face f at (u, v) from the surface's curvature.
  double surface_bound(int f, Vec2 uv) const;
  // Size along edge e at parameter t, where s in [0, 1] is the arc-length fraction from the
  // first vertex: the vertex sizes interpolated, bounded by the curvature of the edge and of
  // the faces it bounds (so a fillet's straight edges are as fine as its section).
  double edge_size(int e, double t, double s) const;

 private:
  const CadModel& cad_;
  double h_;
  double h_min_;            // smallest size anywhere (curvature floor or a vertex size)
  double floor_;            // smallest size any automatic bound may ask for
  double curvature_floor_;  // smallest size the curvature bound may ask for (>= floor_)
  int curvature_;
  bool graded_;  // any --size-at face or curvature bound: graded_vertex_size_ is used
  std::vector<double> vertex_size_;  // global and --size-at vertex sizes (interpolated along edges)
  // The smallest --size-at face size or curvature bound around the vertex: edges leaving it grow
  // from it at kFaceSizeGrading per mm (infinite when none).
  std::vector<double> graded_vertex_size_;
  std::vector<double> face_edge_size_;  // the same for the edge (infinite when none)
  // For each edge, the faces it bounds with one coedge index in each (for the pcurve).
  std::vector<std::vector<std::pair<int, int>>> edge_uses_;
};

}  // namespace hexfem
