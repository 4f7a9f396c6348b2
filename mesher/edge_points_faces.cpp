// The edge points as each face sees them (edge_points.hpp): its boundary in the parameter plane,
// its corners and their angles, and the crossings of its boundary segments (which make
// discretise_edges refine the edges involved). Split from edge_points.cpp, which places the
// points.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "mesher/edge_points.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/rtree2d.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

namespace bgi = boost::geometry::index;
using BPoint = rt2::Point;
using BBox = rt2::Box;
using v3::norm;

}  // namespace

FaceBoundary face_boundary(const CadModel& cad, int f, const EdgePoints& p) {
  FaceBoundary b;
  const auto& ces = cad.coedges(f);
  const auto bounds = cad.uv_bounds(f);
  const double gap_tol = 1e-7 * std::max({bounds[1] - bounds[0], bounds[3] - bounds[2], 1e-300});
  std::size_t c0 = 0;
  while (c0 < ces.size()) {
    std::size_t c1 = c0;
    while (c1 < ces.size() && ces[c1].wire == ces[c0].wire) ++c1;
    const int first_point = static_cast<int>(b.uv.size());
    for (std::size_t c = c0; c < c1; ++c) {
      const CoEdge& ce = ces[c];
      const auto& ts = p.t[static_cast<std::size_t>(ce.edge - 1)];
      const auto& nodes = p.node[static_cast<std::size_t>(ce.edge - 1)];
      const std::size_t n = ts.size();
      auto index = [&](std::size_t k) { return ce.reversed ? n - 1 - k : k; };
      const int ci = static_cast<int>(c);
      for (std::size_t k = 0; k + 1 < n; ++k) {
        b.uv.push_back(cad.coedge_uv(f, ci, ts[index(k)]));
        b.node.push_back(nodes[index(k)]);
        b.coedge.push_back(ci);
        b.prev_coedge.push_back(k == 0 ? static_cast<int>(c == c0 ? c1 - 1 : c - 1) : -1);
        b.t.push_back(ts[index(k)]);
      }
      // The next coedge normally starts at this one's end: the end point is then the next
      // one's first point (pcurves that miss each other by a tolerance are snapped together,
      // else they could cross). Where the next coedge starts elsewhere (another vertex, a
      // wire taken out of order, a full period away), the end is kept as its own point.
      const std::size_t next = c + 1 < c1 ? c + 1 : c0;
      const auto& nce = ces[next];
      const auto& nts = p.t[static_cast<std::size_t>(nce.edge - 1)];
      const auto& nnodes = p.node[static_cast<std::size_t>(nce.edge - 1)];
      const double tn = nce.reversed ? nts.back() : nts.front();
      const int next_node = nce.reversed ? nnodes.back() : nnodes.front();
      const Vec2 end = cad.coedge_uv(f, ci, ts[index(n - 1)]);
      const Vec2 start = cad.coedge_uv(f, static_cast<int>(next), tn);
      const Vec2 before = cad.coedge_uv(f, ci, ts[index(n - 2)]);
      const double gap = std::hypot(end[0] - start[0], end[1] - start[1]);
      const double last_len = std::hypot(end[0] - before[0], end[1] - before[1]);
      const bool snap = nodes[index(n - 1)] == next_node && gap <= 0.25 * last_len;
      if (!snap && gap > gap_tol) {
        b.uv.push_back(end);
        b.node.push_back(nodes[index(n - 1)]);
        b.coedge.push_back(ci);
        b.prev_coedge.push_back(-1);
        b.t.push_back(ts[index(n - 1)]);
      }
    }
    const int last_point = static_cast<int>(b.uv.size());
    for (int i = first_point; i < last_point; ++i)
      b.segments.push_back({i, i + 1 < last_point ? i + 1 : first_point});
    c0 = c1;
  }
  // A vertex met by two wires (a hole touching the outer boundary) gets one (u, v), not two
  // that differ by the pcurves' tolerance and would overlap.
  std::unordered_map<int, std::vector<std::size_t>> seen;
  const double snap_tol = 1e-6 * std::max(bounds[1] - bounds[0], bounds[3] - bounds[2]);
  for (std::size_t i = 0; i < b.uv.size(); ++i) {
    auto& list = seen[b.node[i]];
    for (std::size_t j : list) {
      if (std::hypot(b.uv[i][0] - b.uv[j][0], b.uv[i][1] - b.uv[j][1]) <= snap_tol) {
        b.uv[i] = b.uv[j];
        break;
      }
    }
    list.push_back(i);
  }
  // A damaged pcurve (a NaN in the file) would reach CGAL's exact arithmetic, which GMP ends
  // with SIGFPE (the fuzz, seed 53).
  for (const Vec2& uv : b.uv)
    if (!std::isfinite(uv[0]) || !std::isfinite(uv[1]))
      throw Error("face " + std::to_string(f) +
                  ": a point of its boundary has no finite parameter (a damaged curve on the "
                  "face in the CAD file)");
  // Two boundary points a rounding error apart (an edge whose pcurve collapsed onto a corner in
  // a damaged file) make CGAL's refinement walk for ever (the fuzz, seed 67); a sound face's
  // points are at least a tiny fraction of its extent apart.
  const double min_gap = 1e-12 * std::max({bounds[1] - bounds[0], bounds[3] - bounds[2], 1e-300});
  for (const auto& [i, j] : b.segments)
    if (std::hypot(b.uv[i][0] - b.uv[j][0], b.uv[i][1] - b.uv[j][1]) < min_gap &&
        b.node[i] != b.node[j])
      throw Error("face " + std::to_string(f) +
                  ": two points of its boundary coincide in the parameter plane (a damaged curve "
                  "on the face in the CAD file)");
  return b;
}

std::vector<FaceCorner> face_corners(const CadModel& cad, int f) {
  const auto& ces = cad.coedges(f);
  // Direction from the coedge's vertex at its start (leaving) or end (arriving, reversed
  // so it also points away from the vertex): a chord a ten-thousandth of the edge long,
  // which is the tangent at a corner and still tells the sides apart at a tangent cusp.
  auto away = [&](const CoEdge& ce, bool at_start, double& t_vertex) -> Vec3 {
    const Vec2 r = cad.edge_range(ce.edge);
    const bool first = at_start != ce.reversed;  // the vertex is at the edge's first end
    t_vertex = first ? r[0] : r[1];
    const double t = t_vertex + (first ? 1 : -1) * 1e-4 * (r[1] - r[0]);
    return v3::sub(cad.edge_point(ce.edge, t), cad.edge_point(ce.edge, t_vertex));
  };
  std::vector<FaceCorner> out;
  std::size_t c0 = 0;
  while (c0 < ces.size()) {
    std::size_t c1 = c0;
    while (c1 < ces.size() && ces[c1].wire == ces[c0].wire) ++c1;
    for (std::size_t c = c0; c < c1; ++c) {
      const std::size_t prev = c == c0 ? c1 - 1 : c - 1;
      const CoEdge &in = ces[prev], &ce = ces[c];
      const auto ends = cad.edge_vertices(ce.edge);
      FaceCorner k;
      k.vertex = ends[ce.reversed ? 1 : 0];
      k.in_coedge = static_cast<int>(prev);
      k.out_coedge = static_cast<int>(c);
      k.angle = std::numeric_limits<double>::quiet_NaN();
      if (!cad.edge_degenerate(in.edge) && !cad.edge_degenerate(ce.edge) &&
          (ends[ce.reversed ? 1 : 0] == cad.edge_vertices(in.edge)[in.reversed ? 0 : 1])) {
        double t_out = 0, t_in = 0;
        Vec3 a = away(ce, true, t_out);
        Vec3 b = away(in, false, t_in);
        const SurfaceDerivs d = cad.eval(f, cad.coedge_uv(f, static_cast<int>(c), t_out));
        Vec3 n = v3::cross(d.du, d.dv);
        const double ln = norm(n);
        if (ln > 1e-14 * norm(d.du) * norm(d.dv) && ln > 0) {
          n = v3::scaled(n, 1 / ln);
          a = v3::sub(a, v3::scaled(n, v3::dot(a, n)));
          b = v3::sub(b, v3::scaled(n, v3::dot(b, n)));
          if (norm(a) > 0 && norm(b) > 0) {
            // The face lies to the left of the leaving direction (wires run with the face on
            // their left in the parameter plane, n = du x dv): the interior angle turns
            // counter-clockwise from a to b.
            double ang = std::atan2(v3::dot(n, v3::cross(a, b)), v3::dot(a, b)) * 180 /
                         3.14159265358979323846;
            if (ang < 0) ang += 360;
            k.angle = ang;
          }
        }
      }
      out.push_back(k);
    }
    c0 = c1;
  }
  return out;
}

std::vector<std::array<int, 2>> crossing_segments(const FaceBoundary& b) {
  const std::vector<std::pair<BBox, int>> boxes = rt2::segment_boxes(b.uv, b.segments);
  rt2::BoxTree tree(boxes.begin(), boxes.end());
  auto orient = [](const Vec2& p, const Vec2& q, const Vec2& r) {
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
  };
  std::vector<std::array<int, 2>> out;
  std::vector<std::pair<BBox, int>> hits;
  for (const auto& [box, s] : boxes) {
    hits.clear();
    tree.query(bgi::intersects(box), std::back_inserter(hits));
    const auto& sa = b.segments[static_cast<std::size_t>(s)];
    for (const auto& [ob, o] : hits) {
      if (o <= s) continue;
      const auto& sb = b.segments[static_cast<std::size_t>(o)];
      const Vec2 &p1 = b.uv[static_cast<std::size_t>(sa[0])],
                 &p2 = b.uv[static_cast<std::size_t>(sa[1])];
      const Vec2 &q1 = b.uv[static_cast<std::size_t>(sb[0])],
                 &q2 = b.uv[static_cast<std::size_t>(sb[1])];
      // Segments meeting at an end point (consecutive ones, or two wires touching at a
      // vertex) are not crossing.
      if (p1 == q1 || p1 == q2 || p2 == q1 || p2 == q2) continue;
      const double d1 = orient(p1, p2, q1), d2 = orient(p1, p2, q2);
      const double d3 = orient(q1, q2, p1), d4 = orient(q1, q2, p2);
      // Touching counts as crossing: a point on another segment would split a constraint.
      if (d1 * d2 <= 0 && d3 * d4 <= 0 && !(d1 == 0 && d2 == 0)) out.push_back({s, o});
    }
  }
  return out;
}

}  // namespace hexfem
