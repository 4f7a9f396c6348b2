#include "mesher/cad/cad_project.hpp"

#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Standard_Failure.hxx>
#include <algorithm>
#include <limits>

#include "mesher/cad/cad_impl.hpp"

namespace hexfem {

std::optional<Vec3> closest_point_on_geometry(const CadModel& cad, const Vec3& p, int f1, int f2) {
  const CadModel::Impl& m = cad.impl();
  const gp_Pnt q(p[0], p[1], p[2]);
  if (f1 < 1 || f2 < 1 || f1 > cad.num_faces() || f2 > cad.num_faces()) return std::nullopt;
  try {
    if (f1 == f2) {
      const FaceData& d = m.faces[f1 - 1];
      GeomAPI_ProjectPointOnSurf proj(q, d.surface, d.bounds[0], d.bounds[1], d.bounds[2],
                                      d.bounds[3]);
      if (proj.NbPoints() == 0) return std::nullopt;
      return to_vec(proj.NearestPoint());
    }
    std::optional<Vec3> best;
    double best_d = std::numeric_limits<double>::infinity();
    for (const EdgeData& e : m.edges) {
      if (e.degenerate || e.curve.IsNull()) continue;
      const auto has = [&](int f) {
        return std::find(e.faces.begin(), e.faces.end(), f) != e.faces.end();
      };
      if (!has(f1) || !has(f2)) continue;
      GeomAPI_ProjectPointOnCurve proj(q, e.curve, e.first, e.last);
      if (proj.NbPoints() == 0) continue;
      if (proj.LowerDistance() < best_d) {
        best_d = proj.LowerDistance();
        best = to_vec(proj.NearestPoint());
      }
    }
    return best;
  } catch (const Standard_Failure&) {
    return std::nullopt;
  }
}

}  // namespace hexfem
