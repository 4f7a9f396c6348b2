#include "mesher/size_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "mesher/mesh/error.hpp"

namespace hexfem {

SizeField::SizeField(const CadModel& cad, const SizeOptions& options)
    : cad_(cad),
      h_(options.h),
      curvature_(options.curvature),
      graded_(!options.face_sizes.empty() || !options.edge_sizes.empty()) {
  if (!(h_ > 0) || !std::isfinite(h_))
    throw Error("the mesh size h must be > 0 (got " + std::to_string(h_) + ")");
  if (curvature_ < 0) throw Error("--curvature must be >= 0 elements per 2*pi");
  if (curvature_ > 0 && curvature_ < 3)
    throw Error("--curvature must be at least 3 elements per 2*pi");
  vertex_size_.assign(static_cast<std::size_t>(cad.num_vertices()), h_);
  floor_ = h_ * options.min_ratio;
  curvature_floor_ = h_ * std::max(options.min_ratio, options.curvature_min_ratio);
  h_min_ = curvature_ > 0 ? curvature_floor_ : h_;
  // Below the smallest size the edge points no longer grade away from the vertex in a few dozen
  // steps (1e-7 on the steel part: 16,000 edge points, 28 s; 1e-9 ran for minutes).
  const double smallest = kMinRelativeSize * cad.bbox().diagonal();
  auto check_size = [smallest](const char* what, int id, double s) {
    char msg[200];
    if (!(s > 0) || !std::isfinite(s)) {
      std::snprintf(msg, sizeof msg, "--size-at %s:%d: size must be > 0", what, id);
      throw Error(msg);
    }
    if (s < smallest) {
      std::snprintf(msg, sizeof msg,
                    "--size-at %s:%d=%g: sizes below %g mm (1e-5 of the part's diagonal) are "
                    "not resolved",
                    what, id, s, smallest);
      throw Error(msg);
    }
  };
  for (const auto& [v, s] : options.vertex_sizes) {
    if (v < 1 || v > cad.num_vertices())
      throw Error("--size-at: no vertex " + std::to_string(v) + " (the part has " +
                  std::to_string(cad.num_vertices()) + " vertices)");
    check_size("vertex", v, s);
    vertex_size_[static_cast<std::size_t>(v - 1)] = s;
    h_min_ = std::min(h_min_, s);
  }
  constexpr double kNone = std::numeric_limits<double>::infinity();
  graded_vertex_size_.assign(vertex_size_.size(), kNone);
  face_edge_size_.assign(static_cast<std::size_t>(cad.num_edges()), kNone);
  // An edge at size s: its ends too, from which the edges leaving them grow back.
  auto size_edge = [&](int e, double s) {
    auto& es = face_edge_size_[static_cast<std::size_t>(e - 1)];
    es = std::min(es, s);
    for (int v : cad.edge_vertices(e))
      if (v > 0) {
        auto& vs = graded_vertex_size_[static_cast<std::size_t>(v - 1)];
        vs = std::min(vs, s);
      }
  };
  for (const auto& [f, s] : options.face_sizes) {
    if (f < 1 || f > cad.num_faces())
      throw Error("--size-at: no face " + std::to_string(f) + " (the part has " +
                  std::to_string(cad.num_faces()) + " faces)");
    check_size("face", f, s);
    h_min_ = std::min(h_min_, s);
    for (const CoEdge& ce : cad.coedges(f)) size_edge(ce.edge, s);
  }
  for (const auto& [e, s] : options.edge_sizes) {
    if (e < 1 || e > cad.num_edges())
      throw Error("--size-at: no edge " + std::to_string(e) + " (the part has " +
                  std::to_string(cad.num_edges()) + " edges)");
    check_size("edge", e, s);
    h_min_ = std::min(h_min_, s);
    size_edge(e, s);
  }
  edge_uses_.resize(static_cast<std::size_t>(cad.num_edges()));
  for (int f = 1; f <= cad.num_faces(); ++f) {
    const auto& ces = cad.coedges(f);
    for (std::size_t c = 0; c < ces.size(); ++c) {
      auto& uses = edge_uses_[static_cast<std::size_t>(ces[c].edge - 1)];
      if (std::none_of(uses.begin(), uses.end(), [f](const auto& p) { return p.first == f; }))
        uses.emplace_back(f, static_cast<int>(c));
    }
  }
  // A vertex takes the curvature bound of the edges and faces around it, so that every edge
  // leaving it (a straight seam below a small fillet) starts from the size its neighbourhood
  // asks for and grows back at kFaceSizeGrading, like a --size-at face. (Interpolating it
  // linearly along the edge, as before, spread a fillet's size along whole straight edges: at
  // --curvature 12 the shared models at diagonal/30 had 1.0-7.1x the vertices.)
  if (curvature_ > 0) {
    graded_ = true;
    std::vector<double> bound(vertex_size_.size(), std::numeric_limits<double>::infinity());
    for (int e = 1; e <= cad.num_edges(); ++e) {
      if (cad.edge_degenerate(e)) continue;
      const auto ends = cad.edge_vertices(e);
      const Vec2 range = cad.edge_range(e);
      for (int k = 0; k < 2; ++k) {
        if (ends[k] <= 0) continue;
        double b = curvature_bound(cad.edge_curvature(e, range[k]));
        for (const auto& [f, c] : edge_uses_[static_cast<std::size_t>(e - 1)])
          b = std::min(b, surface_bound(f, cad.coedge_uv(f, c, range[k])));
        auto& vb = bound[static_cast<std::size_t>(ends[k] - 1)];
        vb = std::min(vb, b);
      }
    }
    for (std::size_t v = 0; v < vertex_size_.size(); ++v)
      graded_vertex_size_[v] = std::min(graded_vertex_size_[v], bound[v]);
  }
}

double SizeField::curvature_bound(double kappa) const {
  if (curvature_ <= 0 || !(kappa > 0)) return std::numeric_limits<double>::infinity();
  return std::max(2 * std::numbers::pi / (curvature_ * kappa), curvature_floor_);
}

double SizeField::surface_bound(int f, Vec2 uv) const {
  if (curvature_ <= 0 || cad_.surface_type(f) == SurfaceType::Plane)
    return std::numeric_limits<double>::infinity();
  return curvature_bound(cad_.max_curvature(f, uv));
}

double SizeField::edge_size(int e, double t, double s) const {
  const auto [v0, v1] = cad_.edge_vertices(e);
  const double h0 = v0 > 0 ? vertex_size_[static_cast<std::size_t>(v0 - 1)] : h_;
  const double h1 = v1 > 0 ? vertex_size_[static_cast<std::size_t>(v1 - 1)] : h_;
  s = std::clamp(s, 0.0, 1.0);
  double size = h0 + (h1 - h0) * s;
  if (curvature_ > 0) {
    size = std::min(size, curvature_bound(cad_.edge_curvature(e, t)));
    for (const auto& [f, c] : edge_uses_[static_cast<std::size_t>(e - 1)])
      size = std::min(size, surface_bound(f, cad_.coedge_uv(f, c, t)));
  }
  if (graded_) {
    size = std::min(size, face_edge_size_[static_cast<std::size_t>(e - 1)]);
    const double length = cad_.edge_length(e);
    if (v0 > 0)
      size = std::min(size, graded_vertex_size_[static_cast<std::size_t>(v0 - 1)] +
                                kFaceSizeGrading * s * length);
    if (v1 > 0)
      size = std::min(size, graded_vertex_size_[static_cast<std::size_t>(v1 - 1)] +
                                kFaceSizeGrading * (1 - s) * length);
  }
  return size;
}

}  // namespace hexfem
