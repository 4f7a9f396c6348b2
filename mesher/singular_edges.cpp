#include "mesher/singular_edges.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

// Unit direction in face f, at parameter t of its coedge c, perpendicular to the edge and
// pointing into the face; none where the face's trimmed domain does not tell (both or neither
// side inside).
std::optional<Vec3> into_face(const CadModel& cad, int f, int c, double t, double dt, double step) {
  const Vec2 uv = cad.coedge_uv(f, c, t);
  const Vec2 a = cad.coedge_uv(f, c, t - dt), b = cad.coedge_uv(f, c, t + dt);
  const Vec2 tau{b[0] - a[0], b[1] - a[1]};
  const SurfaceDerivs d = cad.eval(f, uv);
  // The perpendicular in the parameter plane, scaled to move `step` in space.
  const Vec2 perp{-tau[1], tau[0]};
  const Vec3 w = v3::add(v3::scaled(d.du, perp[0]), v3::scaled(d.dv, perp[1]));
  const double len = v3::norm(w);
  if (!(len > 0)) return std::nullopt;
  const double s = step / len;
  const bool plus = cad.contains(f, {uv[0] + s * perp[0], uv[1] + s * perp[1]});
  const bool minus = cad.contains(f, {uv[0] - s * perp[0], uv[1] - s * perp[1]});
  if (plus == minus) return std::nullopt;
  const double sign = plus ? 1.0 : -1.0;
  return v3::scaled(w, sign / len);
}

int coedge_index(const CadModel& cad, int f, int e) {
  const auto& ces = cad.coedges(f);
  int found = -1;
  for (std::size_t c = 0; c < ces.size(); ++c)
    if (ces[c].edge == e) {
      if (found >= 0 || ces[c].seam) return -1;  // a seam: the face on both sides
      found = static_cast<int>(c);
    }
  return found;
}

}  // namespace

std::vector<int> reentrant_edges(const CadModel& cad, double min_turn_deg) {
  const double min_sin = std::sin(min_turn_deg * std::numbers::pi / 180.0);
  std::vector<int> out;
  for (int e = 1; e <= cad.num_edges(); ++e) {
    if (cad.edge_degenerate(e)) continue;
    const auto& faces = cad.faces_of_edge(e);
    if (faces.size() != 2 || faces[0] == faces[1]) continue;
    const int c0 = coedge_index(cad, faces[0], e), c1 = coedge_index(cad, faces[1], e);
    if (c0 < 0 || c1 < 0) continue;
    const Vec2 range = cad.edge_range(e);
    const double dt = 1e-4 * (range[1] - range[0]);
    const double step = 1e-3 * cad.edge_length(e);
    bool concave = true;
    for (double s : {0.25, 0.5, 0.75}) {
      const double t = range[0] + s * (range[1] - range[0]);
      const auto d0 = into_face(cad, faces[0], c0, t, dt, step);
      const auto d1 = into_face(cad, faces[1], c1, t, dt, step);
      if (!d0 || !d1) {
        concave = false;
        break;
      }
      const Vec3 n0 = cad.normal(faces[0], cad.coedge_uv(faces[0], c0, t));
      const Vec3 n1 = cad.normal(faces[1], cad.coedge_uv(faces[1], c1, t));
      // Each face turns towards the other's outside: the solid wraps round the edge.
      if (!(v3::dot(*d0, n1) > min_sin && v3::dot(*d1, n0) > min_sin)) {
        concave = false;
        break;
      }
    }
    if (concave) out.push_back(e);
  }
  return out;
}

std::vector<int> rim_edges(const CadModel& cad, const std::vector<int>& faces) {
  std::vector<int> set = faces;
  std::sort(set.begin(), set.end());
  auto in_set = [&](int f) { return std::binary_search(set.begin(), set.end(), f); };
  std::vector<int> out;
  for (int f : set)
    for (const CoEdge& ce : cad.coedges(f)) {
      const auto& around = cad.faces_of_edge(ce.edge);
      if (std::any_of(around.begin(), around.end(), [&](int g) { return !in_set(g); }))
        out.push_back(ce.edge);
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace hexfem
