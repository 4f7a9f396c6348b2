#include "mesher/cad/cad_project.hpp"

#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Standard_Failure.hxx>
#include <algorithm>
#include <limits>

#include "mesher/cad/cad_impl.hpp"

namespace hexfem {

namespace {

bool valid_faces(const CadModel& cad, int f1, int f2) {
  return f1 >= 1 && f2 >= 1 && f1 <= cad.num_faces() && f2 <= cad.num_faces();
}

// The edges (indices, in the model's order) that faces f1 and f2 both bound.
std::vector<int> shared_edges(const CadModel::Impl& m, int f1, int f2) {
  std::vector<int> out;
  for (std::size_t i = 0; i < m.edges.size(); ++i) {
    const EdgeData& e = m.edges[i];
    if (e.degenerate || e.curve.IsNull()) continue;
    const auto has = [&](int f) {
      return std::find(e.faces.begin(), e.faces.end(), f) != e.faces.end();
    };
    if (has(f1) && has(f2)) out.push_back(static_cast<int>(i));
  }
  return out;
}

// The nearest of the projections onto the edges, the first one on a tie (the model's order).
template <class Project>
std::optional<Vec3> nearest_on_edges(const std::vector<int>& edges, Project&& project) {
  std::optional<Vec3> best;
  double best_d = std::numeric_limits<double>::infinity();
  for (const int i : edges) {
    GeomAPI_ProjectPointOnCurve& proj = project(i);
    if (proj.NbPoints() == 0) continue;
    if (proj.LowerDistance() < best_d) {
      best_d = proj.LowerDistance();
      best = to_vec(proj.NearestPoint());
    }
  }
  return best;
}

}  // namespace

std::optional<Vec3> closest_point_on_geometry(const CadModel& cad, const Vec3& p, int f1, int f2) {
  const CadModel::Impl& m = cad.impl();
  const gp_Pnt q(p[0], p[1], p[2]);
  if (!valid_faces(cad, f1, f2)) return std::nullopt;
  try {
    if (f1 == f2) {
      const FaceData& d = m.faces[f1 - 1];
      GeomAPI_ProjectPointOnSurf proj(q, d.surface, d.bounds[0], d.bounds[1], d.bounds[2],
                                      d.bounds[3]);
      if (proj.NbPoints() == 0) return std::nullopt;
      return to_vec(proj.NearestPoint());
    }
    GeomAPI_ProjectPointOnCurve proj;
    return nearest_on_edges(shared_edges(m, f1, f2), [&](int i) -> GeomAPI_ProjectPointOnCurve& {
      const EdgeData& e = m.edges[i];
      proj.Init(q, e.curve, e.first, e.last);
      return proj;
    });
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

struct GeometryProjector::Cache {
  std::map<int, GeomAPI_ProjectPointOnSurf> faces;
  std::map<int, GeomAPI_ProjectPointOnCurve> edges;
  std::map<std::pair<int, int>, std::vector<int>> shared;
};

GeometryProjector::GeometryProjector(const CadModel& cad)
    : cad_(&cad), cache_(std::make_unique<Cache>()) {}
GeometryProjector::~GeometryProjector() = default;
GeometryProjector::GeometryProjector(GeometryProjector&&) noexcept = default;

std::optional<Vec3> GeometryProjector::closest(const Vec3& p, int f1, int f2) {
  const CadModel::Impl& m = cad_->impl();
  const gp_Pnt q(p[0], p[1], p[2]);
  if (!valid_faces(*cad_, f1, f2)) return std::nullopt;
  try {
    if (f1 == f2) {
      auto [it, added] = cache_->faces.try_emplace(f1);
      GeomAPI_ProjectPointOnSurf& proj = it->second;
      if (added) {
        const FaceData& d = m.faces[f1 - 1];
        proj.Init(d.surface, d.bounds[0], d.bounds[1], d.bounds[2], d.bounds[3]);
      }
      proj.Perform(q);
      if (proj.NbPoints() == 0) return std::nullopt;
      return to_vec(proj.NearestPoint());
    }
    auto [sit, new_pair] = cache_->shared.try_emplace({std::min(f1, f2), std::max(f1, f2)});
    if (new_pair) sit->second = shared_edges(m, f1, f2);
    return nearest_on_edges(sit->second, [&](int i) -> GeomAPI_ProjectPointOnCurve& {
      auto [it, added] = cache_->edges.try_emplace(i);
      if (added) {
        const EdgeData& e = m.edges[i];
        it->second.Init(e.curve, e.first, e.last);
      }
      it->second.Perform(q);
      return it->second;
    });
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

}  // namespace hexfem
