#include "mesher/edge_points.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "mesher/mesh/error.hpp"
#include "mesher/rtree2d.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using BPoint = rt2::Point;
using BBox = rt2::Box;
using v3::norm;

// Size bounds along each edge from the previous round (narrow faces, gradation): a
// piecewise-linear function of t through that round's points, (t, bound) sorted by t.
using Caps = std::vector<std::vector<std::pair<double, double>>>;

double cap_at(const Caps& caps, int e, double t) {
  const auto& c = caps[static_cast<std::size_t>(e - 1)];
  if (c.empty()) return std::numeric_limits<double>::infinity();
  const auto it =
      std::lower_bound(c.begin(), c.end(), t,
                       [](const std::pair<double, double>& a, double x) { return a.first < x; });
  if (it == c.begin()) return it->second;
  if (it == c.end()) return c.back().second;
  const auto prev = it - 1;
  const double span = it->first - prev->first;
  const double w = span != 0 ? (t - prev->first) / span : 0.0;
  return prev->second + w * (it->second - prev->second);
}

// Face corners sharper than kSharpCorner (degrees) get a corner zone (below) on both their
// edges.
constexpr double kSharpCorner = 5;
// Across a sharp corner the points are spaced kWedgeSpacing times the width between its edges:
// the triangles spanning the wedge keep angles near atan(1 / kWedgeSpacing), and the step from
// the zone's long first segment to the next stays moderate (a ratio of 1 / (kWedgeSpacing *
// corner angle)) for the face on the other side of the edge.
constexpr double kWedgeSpacing = 4;

struct Bounds {
  Caps caps;

  // Per edge, the radius of the zone at its first and last vertex (0: none) where a sharp
  // face corner is: the edge's first point sits that far from the vertex, so the corner is
  // one triangle, whose angle at the vertex is the corner's. Finer points there would only
  // cut the corner into thinner triangles; beyond it the narrow-face sizes (the width across
  // the corner) grade the spacing, so the triangles between the two edges keep their shape.
  std::vector<std::array<double, 2>> zone;
};

// Size along edge e at parameter t (s: arc-length fraction, r_first / r_last: distance from
// its first / last vertex).
double capped_size(const SizeField& size, const Bounds& b, int e, double t, double s,
                   double r_first, double r_last) {
  const auto& z = b.zone[static_cast<std::size_t>(e - 1)];
  if (z[0] > 0 && r_first < z[0]) return z[0];
  if (z[1] > 0 && r_last < z[1]) return z[1];
  return std::min(size.edge_size(e, t, s), cap_at(b.caps, e, t));
}

constexpr double kMaxEdgePoints = 1e6;

// Parameters of the points on edge e: equal steps of the integral of 1/size over arc length,
// `density` times as many as the size field asks for.
std::vector<double> edge_parameters(const CadModel& cad, const SizeField& size,
                                    const Bounds& bounds, int e, double density) {
  const Vec2 range = cad.edge_range(e);
  if (cad.edge_degenerate(e)) return {range[0], range[1]};
  const double length = cad.edge_length(e);
  double finest = size.min_size();
  for (const auto& c : bounds.caps[static_cast<std::size_t>(e - 1)])
    finest = std::min(finest, c.second);
  for (double z : bounds.zone[static_cast<std::size_t>(e - 1)])
    if (z > 0) finest = std::min(finest, z);
  const int samples = static_cast<int>(std::clamp(std::ceil(6 * length / finest), 32.0, 20000.0));
  std::vector<double> ts(samples + 1), arc(samples + 1, 0.0), dens(samples + 1, 0.0);
  double max_kl = 0;
  for (int i = 0; i <= samples; ++i) ts[i] = range[0] + (range[1] - range[0]) * i / samples;
  for (int i = 1; i <= samples; ++i) {
    // Midpoint rule for the arc length of the sub-interval.
    const double tm = 0.5 * (ts[i - 1] + ts[i]);
    arc[i] = arc[i - 1] + norm(cad.edge_derivative(e, tm)) * (ts[i] - ts[i - 1]);
  }
  const double total = arc[samples] > 0 ? arc[samples] : 1.0;
  // Corner zones: exactly one segment each, the other points spread over the rest. Not on an
  // edge refined for crossings (the zone's segment may be the one crossing).
  std::array<double, 2> z = bounds.zone[static_cast<std::size_t>(e - 1)];
  if (density != 1.0 || z[0] + z[1] > 0.9 * total) z = {0, 0};
  auto param_at = [&](double a) {  // the parameter at arc length a
    const auto it = std::lower_bound(arc.begin(), arc.end(), a);
    if (it == arc.begin()) return ts.front();
    if (it == arc.end()) return ts.back();
    const auto i = static_cast<std::size_t>(it - arc.begin());
    const double span = arc[i] - arc[i - 1];
    return ts[i - 1] + (span > 0 ? (a - arc[i - 1]) / span : 0.5) * (ts[i] - ts[i - 1]);
  };
  for (int i = 0; i <= samples; ++i) {
    const bool in_zone = arc[i] < z[0] || total - arc[i] < z[1];
    dens[i] = in_zone ? 0.0
                      : 1.0 / std::min(size.edge_size(e, ts[i], arc[i] / total),
                                       cap_at(bounds.caps, e, ts[i]));
    if (i % 4 == 0) max_kl = std::max(max_kl, cad.edge_curvature(e, ts[i]) * length);
  }
  std::vector<double> integral(samples + 1, 0.0);
  for (int i = 1; i <= samples; ++i)
    integral[i] = integral[i - 1] + 0.5 * (dens[i] + dens[i - 1]) * (arc[i] - arc[i - 1]);
  // No sound request puts a million points on one edge (a surface of about 1e12): a vertex
  // thrown far away by a corrupt file does, and would exhaust the memory point by point.
  const double wanted = integral[samples] * density;
  if (!(wanted <= kMaxEdgePoints)) {
    char msg[240];
    std::snprintf(msg, sizeof msg,
                  "edge %d (%.4g mm long) would take about %.3g points at the sizes asked (limit "
                  "%.0e); the CAD geometry or the size is off",
                  e, length, wanted, kMaxEdgePoints);
    throw Error(msg);
  }
  const bool closed = cad.edge_closed(e);
  // A curved edge gets two segments at least (one chord would be shared by both its faces as
  // a fold), unless it is short against the size (a tenth): its sagitta is then nothing, and
  // a midpoint would leave a flat sliver of a triangle in a face that small.
  const auto ends = cad.edge_vertices(e);
  const bool curved = max_kl > 1e-3 &&
                      length > 0.1 * std::min(size.vertex_size(ends[0]), size.vertex_size(ends[1]));
  const int min_segments = closed ? 3 : (curved ? 2 : 1);
  const int zones = (z[0] > 0 ? 1 : 0) + (z[1] > 0 ? 1 : 0);
  const int n = std::max(
      min_segments - zones,
      std::max(zones > 0 ? 1 : 0, static_cast<int>(std::lround(integral[samples] * density))));
  std::vector<double> out{range[0]};
  if (z[0] > 0) out.push_back(param_at(z[0]));
  int j = 1;
  for (int k = 1; k < n; ++k) {
    const double target = integral[samples] * k / n;
    while (j < samples && integral[j] < target) ++j;
    const double span = integral[j] - integral[j - 1];
    const double w = span > 0 ? (target - integral[j - 1]) / span : 0.5;
    out.push_back(ts[j - 1] + w * (ts[j] - ts[j - 1]));
  }
  if (z[1] > 0) out.push_back(param_at(total - z[1]));
  out.push_back(range[1]);
  return out;
}

void build_points(const CadModel& cad, const SizeField& size, const Bounds& bounds,
                  const std::vector<double>& density, EdgePoints& p) {
  const int nv = cad.num_vertices();
  p.xyz.clear();
  p.size.clear();
  p.node_edge.assign(static_cast<std::size_t>(nv), 0);
  for (int v = 1; v <= nv; ++v) {
    p.xyz.push_back(cad.vertex_point(v));
    p.size.push_back(size.vertex_size(v));
  }
  p.t.assign(static_cast<std::size_t>(cad.num_edges()), {});
  p.node.assign(static_cast<std::size_t>(cad.num_edges()), {});
  // Micro edges (shorter than a fiftieth of the size at their ends, a CAD artefact) are
  // collapsed: their two vertices become one node, and the triangles that would span them
  // collapse like those at a pole. (A tenth collapsed real features of thin sheet parts and
  // folded their small faces; short edges above the limit get finer sizes around them,
  // short_segment_sizes.)
  std::vector<int> root(static_cast<std::size_t>(nv) + 1);
  for (int v = 0; v <= nv; ++v) root[static_cast<std::size_t>(v)] = v;
  auto find = [&](int v) {
    while (root[static_cast<std::size_t>(v)] != v)
      v = root[static_cast<std::size_t>(v)] =
          root[static_cast<std::size_t>(root[static_cast<std::size_t>(v)])];
    return v;
  };
  std::vector<bool> micro(static_cast<std::size_t>(cad.num_edges()), false);
  for (int e = 1; e <= cad.num_edges(); ++e) {
    const auto [v0, v1] = cad.edge_vertices(e);
    if (v0 <= 0 || v1 <= 0) throw Error("edge " + std::to_string(e) + " has no vertex at an end");
    if (cad.edge_degenerate(e) || v0 == v1) continue;
    const double h = std::min(size.vertex_size(v0), size.vertex_size(v1));
    if (cad.edge_length(e) >= 0.02 * h) continue;
    const int a = find(v0), b = find(v1);
    // A chain of micro edges (a letter's outline in small straight pieces) must not collapse
    // into one node: each vertex stays within the limit of the node it joins, or the edge keeps
    // its own two nodes (40mm_capot at h = 10.98: six 0.15 mm edges, 1 mm in all, became one
    // point, and the embossed letter's face folded over its neighbour).
    if (a != b && (norm(v3::sub(cad.vertex_point(a), cad.vertex_point(v1))) >= 0.02 * h ||
                   norm(v3::sub(cad.vertex_point(b), cad.vertex_point(v0))) >= 0.02 * h))
      continue;
    micro[static_cast<std::size_t>(e - 1)] = true;
    if (a != b) root[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  auto vertex_node = [&](int v) { return find(v) - 1; };
  for (int e = 1; e <= cad.num_edges(); ++e) {
    auto& ts = p.t[static_cast<std::size_t>(e - 1)];
    auto& nodes = p.node[static_cast<std::size_t>(e - 1)];
    const auto [v0, v1] = cad.edge_vertices(e);
    if (micro[static_cast<std::size_t>(e - 1)]) {
      const Vec2 r = cad.edge_range(e);
      ts = {r[0], r[1]};
      nodes = {vertex_node(v0), vertex_node(v1)};
      continue;
    }
    ts = edge_parameters(cad, size, bounds, e, density[static_cast<std::size_t>(e - 1)]);
    for (std::size_t i = 0; i < ts.size(); ++i) {
      const bool first = i == 0, last = i + 1 == ts.size();
      const double s =
          ts.size() > 1 ? static_cast<double>(i) / static_cast<double>(ts.size() - 1) : 0.0;
      const Vec3 x = cad.edge_point(e, ts[i]);
      const double h = cad.edge_degenerate(e) ? size.vertex_size(v0)
                                              : capped_size(size, bounds, e, ts[i], s,
                                                            norm(v3::sub(x, cad.vertex_point(v0))),
                                                            norm(v3::sub(x, cad.vertex_point(v1))));
      if (first || last) {
        const int n = vertex_node(first ? v0 : v1);
        nodes.push_back(n);
        p.size[static_cast<std::size_t>(n)] = std::min(p.size[static_cast<std::size_t>(n)], h);
        continue;
      }
      nodes.push_back(static_cast<int>(p.xyz.size()));
      p.xyz.push_back(x);
      p.size.push_back(h);
      p.node_edge.push_back(e);
    }
  }
}

// A face corner meshed with a zone: sharper than kSharpCorner on the CAD model, or as seen
// by the chords at the zone's size (an acute corner on a curved face whose edges close in,
// e.g. 33° at the vertex and 3° a quarter millimetre away): its zone is then made small
// enough that the corner triangle's angle is close to the CAD corner's.
struct SharpCorner {
  int face = 0, vertex = 0;
  std::array<std::pair<int, int>, 2> ends;  // (edge, end at the corner: 0 = first, 1 = last)
  double r0 = 0;                            // zone radius before the sizes met there
};

// The 3D angle at the corner between the chords to the points at arc length ~r on its edges.
double chord_angle(const CadModel& cad, const SharpCorner& c, double r) {
  const Vec3 x = cad.vertex_point(c.vertex);
  Vec3 d[2];
  for (int k = 0; k < 2; ++k) {
    const auto [e, end] = c.ends[static_cast<std::size_t>(k)];
    const Vec2 range = cad.edge_range(e);
    const double t0 = range[static_cast<std::size_t>(end)];
    // March from the vertex until the chord is r long (the speed of the parametrisation at
    // the vertex is a poor guess on some splines), then halve the last step.
    const double speed = norm(cad.edge_derivative(e, t0));
    const double step = (end == 0 ? 1 : -1) *
                        std::min(speed > 0 ? r / speed / 4 : 1e300, 0.02 * (range[1] - range[0]));
    auto chord = [&](double t) { return norm(v3::sub(cad.edge_point(e, t), x)); };
    double lo = t0, hi = t0;
    for (int i = 0; i < 400; ++i) {
      hi = std::clamp(lo + step, range[0], range[1]);
      if (chord(hi) >= r || hi == lo) break;
      lo = hi;
    }
    for (int i = 0; i < 30; ++i) {
      const double mid = 0.5 * (lo + hi);
      (chord(mid) < r ? lo : hi) = mid;
    }
    d[k] = v3::sub(cad.edge_point(e, hi), x);
  }
  return std::atan2(norm(v3::cross(d[0], d[1])), v3::dot(d[0], d[1])) * 180 /
         3.14159265358979323846;
}

std::vector<SharpCorner> sharp_corners(const CadModel& cad, const SizeField& size, double floor,
                                       double narrow_floor) {
  std::vector<SharpCorner> out;
  for (int f = 1; f <= cad.num_faces(); ++f) {
    if (cad.solids_of_face(f).empty()) continue;
    const auto& ces = cad.coedges(f);
    for (const FaceCorner& fc : face_corners(cad, f)) {
      if (!(fc.angle < 90)) continue;  // NaN too
      const CoEdge& in = ces[static_cast<std::size_t>(fc.in_coedge)];
      const CoEdge& out_ce = ces[static_cast<std::size_t>(fc.out_coedge)];
      if (in.edge == out_ce.edge) continue;
      SharpCorner c;
      c.face = f;
      c.vertex = fc.vertex;
      c.ends = {std::pair{in.edge, in.reversed ? 0 : 1},
                std::pair{out_ce.edge, out_ce.reversed ? 1 : 0}};
      double r = size.vertex_size(fc.vertex);
      for (const auto& [e, end] : c.ends) {
        const Vec2 range = cad.edge_range(e);
        r = std::min({r, 0.45 * cad.edge_length(e),
                      size.edge_size(e, range[static_cast<std::size_t>(end)], end)});
      }
      if (fc.angle >= kSharpCorner) {
        // An ordinary corner unless the chords close in at some scale the edge points may
        // take near it (down to the floor of the narrow-face sizes across a corner).
        bool closes_in = false;
        for (double rr = r; rr >= 0.5 * floor && !closes_in; rr *= 0.5)
          closes_in = chord_angle(cad, c, rr) < kSharpCorner;
        if (!closes_in) continue;
        const double enough = std::min(0.9 * fc.angle, kSharpCorner + 1);
        while (r > narrow_floor && chord_angle(cad, c, r) < enough) r *= 0.5;
      }
      c.r0 = r;
      out.push_back(c);
    }
  }
  return out;
}

// Adds width samples for narrow faces: from each edge point of each face, a ray into the face
// (normal to the boundary in the locally isometric parameter plane) to the first segment of
// another edge; the 3D distance to the hit is the face's width there. Lowers target[node] to
// the width, but not below `floor` across an ordinary corner (the rays of an acute corner hit
// its other edge) nor below `narrow_floor` in a strip or across a sharp corner, whose
// triangles need points about as close as the strip is wide.
void narrow_face_sizes(const CadModel& cad, const EdgePoints& p,
                       const std::vector<SharpCorner>& sharp, double floor, double narrow_floor,
                       std::vector<double>& target, std::vector<double>& across_sharp_corners) {
  std::set<std::array<int, 3>> sharp_pair;  // (face, edge, edge)
  for (const SharpCorner& c : sharp) {
    sharp_pair.insert({c.face, c.ends[0].first, c.ends[1].first});
    sharp_pair.insert({c.face, c.ends[1].first, c.ends[0].first});
  }
  for (int f = 1; f <= cad.num_faces(); ++f) {
    if (cad.solids_of_face(f).empty()) continue;
    const FaceBoundary b = face_boundary(cad, f, p);
    const auto& ces = cad.coedges(f);
    std::map<std::pair<int, int>, double> corner;  // (edge, edge) -> smallest corner angle
    for (const FaceCorner& c : face_corners(cad, f)) {
      const int a = ces[static_cast<std::size_t>(c.in_coedge)].edge;
      const int o = ces[static_cast<std::size_t>(c.out_coedge)].edge;
      const double ang = std::isnan(c.angle) ? 0.0 : c.angle;
      for (const auto& key : {std::pair{a, o}, std::pair{o, a}}) {
        const auto [it, fresh] = corner.emplace(key, ang);
        if (!fresh) it->second = std::min(it->second, ang);
      }
    }
    auto edge_of = [&](int pt) {
      return ces[static_cast<std::size_t>(b.coedge[static_cast<std::size_t>(pt)])].edge;
    };
    const std::size_t n = b.uv.size();
    std::vector<int> prev(n, -1), next(n, -1);
    std::vector<std::pair<BBox, int>> boxes;
    for (std::size_t si = 0; si < b.segments.size(); ++si) {
      const auto& seg = b.segments[si];
      next[static_cast<std::size_t>(seg[0])] = seg[1];
      prev[static_cast<std::size_t>(seg[1])] = seg[0];
      const Vec2& a = b.uv[static_cast<std::size_t>(seg[0])];
      const Vec2& c = b.uv[static_cast<std::size_t>(seg[1])];
      boxes.emplace_back(BBox(BPoint(std::min(a[0], c[0]), std::min(a[1], c[1])),
                              BPoint(std::max(a[0], c[0]), std::max(a[1], c[1]))),
                         static_cast<int>(si));
    }
    const rt2::BoxTree tree(boxes.begin(), boxes.end());
    const auto bd = cad.uv_bounds(f);
    const double reach = std::hypot(bd[1] - bd[0], bd[3] - bd[2]);
    std::vector<std::pair<BBox, int>> hits;
    for (std::size_t i = 0; i < n; ++i) {
      const int node = b.node[i];
      if (p.node_edge[static_cast<std::size_t>(node)] == 0 || prev[i] < 0 || next[i] < 0) continue;
      const int e = edge_of(static_cast<int>(i));
      const Vec2& x = b.uv[i];
      const Vec2& xa = b.uv[static_cast<std::size_t>(prev[i])];
      const Vec2& xb = b.uv[static_cast<std::size_t>(next[i])];
      const SurfaceDerivs d = cad.eval(f, x);
      const double su = norm(d.du), sv = norm(d.dv);
      if (!(su > 0) || !(sv > 0)) continue;
      // Tangent in the scaled plane, turned left (the face is on the left of its wires).
      const double tx = (xb[0] - xa[0]) * su, ty = (xb[1] - xa[1]) * sv;
      const double tl = std::hypot(tx, ty);
      if (!(tl > 0)) continue;
      const Vec2 dir{-ty / tl / su, tx / tl / sv};
      const double dl = std::hypot(dir[0], dir[1]);
      const Vec2 end{x[0] + dir[0] / dl * reach, x[1] + dir[1] / dl * reach};
      hits.clear();
      const bg::model::segment<BPoint> ray(BPoint(x[0], x[1]), BPoint(end[0], end[1]));
      tree.query(bgi::intersects(ray), std::back_inserter(hits));
      double best = std::numeric_limits<double>::infinity();
      int hit_edge = 0;
      Vec3 hit{};
      for (const auto& [box, si] : hits) {
        const auto& seg = b.segments[static_cast<std::size_t>(si)];
        if (edge_of(seg[0]) == e) continue;
        const Vec2& a = b.uv[static_cast<std::size_t>(seg[0])];
        const Vec2& c = b.uv[static_cast<std::size_t>(seg[1])];
        // x + s (end - x) = a + w (c - a)
        const double rx = end[0] - x[0], ry = end[1] - x[1];
        const double ex = c[0] - a[0], ey = c[1] - a[1];
        const double den = rx * ey - ry * ex;
        if (den == 0) continue;
        const double s = ((a[0] - x[0]) * ey - (a[1] - x[1]) * ex) / den;
        const double w = ((a[0] - x[0]) * ry - (a[1] - x[1]) * rx) / den;
        if (s <= 1e-12 || w < 0 || w > 1 || s >= best) continue;
        best = s;
        hit_edge = edge_of(seg[0]);
        const Vec3& pa = p.xyz[static_cast<std::size_t>(b.node[static_cast<std::size_t>(seg[0])])];
        const Vec3& pc = p.xyz[static_cast<std::size_t>(b.node[static_cast<std::size_t>(seg[1])])];
        hit = v3::sub(pa, v3::scaled(v3::sub(pa, pc), w));
      }
      if (!std::isfinite(best)) continue;
      const Vec3& px = p.xyz[static_cast<std::size_t>(node)];
      const auto c = corner.find({e, hit_edge});
      const bool sharp_corner = sharp_pair.count({f, e, hit_edge}) > 0;
      const bool ordinary_corner = c != corner.end() && !sharp_corner;
      double& t = (sharp_corner ? across_sharp_corners : target)[static_cast<std::size_t>(node)];
      const double width = norm(v3::sub(hit, px)) * (sharp_corner ? kWedgeSpacing : 1.0);
      t = std::min(t, std::max(width, ordinary_corner ? floor
                                      : sharp_corner  ? 0.1 * narrow_floor
                                                      : narrow_floor));
    }
  }
}

// A boundary segment much shorter than the size at its ends (a short CAD edge, longer than
// the micro-edge limit) faces points a full size away across the face: a needle triangle
// with an angle of about length/size. Its end nodes get a size of kShortEdgeFactor times the
// segment length, and the gradation spreads it, so the angles across it stay above ~15°.
void short_segment_sizes(const EdgePoints& p, double floor, std::vector<double>& target) {
  constexpr double kShortEdgeFactor = 3;
  for (const auto& nodes : p.node) {
    for (std::size_t k = 0; k + 1 < nodes.size(); ++k) {
      const auto a = static_cast<std::size_t>(nodes[k]), b = static_cast<std::size_t>(nodes[k + 1]);
      if (a == b) continue;  // a degenerate or micro edge
      const double len = norm(v3::sub(p.xyz[a], p.xyz[b]));
      const double s = std::max(kShortEdgeFactor * len, floor);
      target[a] = std::min(target[a], s);
      target[b] = std::min(target[b], s);
    }
  }
}

// The corner zones of Bounds: each sharp corner's radius on both its edges, no more than
// `other` (sizes at the points of `p` from every source but the widths across sharp corners:
// a strip of another face, or of this one between other edges) within the zone.
std::vector<std::array<double, 2>> corner_zones(const CadModel& cad,
                                                const std::vector<SharpCorner>& sharp,
                                                const EdgePoints* p = nullptr,
                                                const std::vector<double>* other = nullptr) {
  std::vector<std::array<double, 2>> zone(static_cast<std::size_t>(cad.num_edges()), {0, 0});
  for (const SharpCorner& c : sharp) {
    double r0 = c.r0;
    if (p && other) {
      const Vec3 x = cad.vertex_point(c.vertex);
      // Outward from the vertex along both edges while within the zone, which shrinks to
      // the sizes met there.
      for (const auto& [e, end] : c.ends) {
        const auto& nodes = p->node[static_cast<std::size_t>(e - 1)];
        for (std::size_t k = 0; k < nodes.size(); ++k) {
          const auto n = static_cast<std::size_t>(nodes[end == 0 ? k : nodes.size() - 1 - k]);
          if (norm(v3::sub(p->xyz[n], x)) > r0 && k > 0) break;
          r0 = std::min(r0, (*other)[n]);
        }
      }
    }
    for (const auto& [e, end] : c.ends) {
      double& z = zone[static_cast<std::size_t>(e - 1)][static_cast<std::size_t>(end)];
      z = z > 0 ? std::min(z, r0) : r0;
    }
  }
  return zone;
}

namespace bg3 {
using Point = bg::model::point<double, 3, bg::cs::cartesian>;
using Box = bg::model::box<Point>;
}  // namespace bg3

// Sizes that grow by at most `rate` per unit length from every point's target (in 3D, across
// edges and faces): graded[i] = min_j target[j] + rate |x_i - x_j|. A small size on one edge
// then spreads to the edges around it, instead of facing a coarse edge across a face.
std::vector<double> graded_sizes(const std::vector<Vec3>& x, const std::vector<double>& target,
                                 double hmax, double rate) {
  std::vector<std::pair<bg3::Point, int>> pts;
  pts.reserve(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    pts.emplace_back(bg3::Point(x[i][0], x[i][1], x[i][2]), static_cast<int>(i));
  const bgi::rtree<std::pair<bg3::Point, int>, bgi::rstar<16>> tree(pts.begin(), pts.end());
  std::vector<int> order;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (target[i] < hmax) order.push_back(static_cast<int>(i));
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return target[static_cast<std::size_t>(a)] < target[static_cast<std::size_t>(b)];
  });
  std::vector<double> graded = target;
  // No size grows past the largest target, so the cones reach no farther than that.
  double top = 0;
  for (int j : order) top = std::max(top, target[static_cast<std::size_t>(j)]);
  std::vector<std::pair<bg3::Point, int>> near;
  for (int j : order) {
    const double sj = graded[static_cast<std::size_t>(j)];
    // A point already lowered by a smaller one spreads nothing that one did not (triangle
    // inequality); skipping it keeps dense edges of equal sizes from costing n^2.
    if (sj < target[static_cast<std::size_t>(j)]) continue;
    const double r = (std::min(hmax, top) - sj) / rate;
    if (r <= 0) continue;
    const Vec3& c = x[static_cast<std::size_t>(j)];
    near.clear();
    tree.query(bgi::intersects(bg3::Box(bg3::Point(c[0] - r, c[1] - r, c[2] - r),
                                        bg3::Point(c[0] + r, c[1] + r, c[2] + r))),
               std::back_inserter(near));
    for (const auto& [pt, i] : near) {
      auto& g = graded[static_cast<std::size_t>(i)];
      g = std::min(g, sj + rate * norm(v3::sub(x[static_cast<std::size_t>(i)], c)));
    }
  }
  return graded;
}

}  // namespace

void sizes_from_edge_spacing(const CadModel& cad, EdgePoints& p) {
  // Each edge's segments, and its spacing over its points' sizes.
  const auto ne = static_cast<std::size_t>(cad.num_edges());
  std::vector<std::vector<double>> seg(ne);
  std::vector<double> ratio(ne, 0);
  for (std::size_t e = 0; e < ne; ++e) {
    const auto& nodes = p.node[e];
    if (cad.edge_degenerate(static_cast<int>(e + 1)) || nodes.size() < 2) continue;
    double length = 0, hsum = p.size[static_cast<std::size_t>(nodes[0])];
    for (std::size_t k = 1; k < nodes.size(); ++k) {
      seg[e].push_back(norm(v3::sub(p.xyz[static_cast<std::size_t>(nodes[k])],
                                    p.xyz[static_cast<std::size_t>(nodes[k - 1])])));
      length += seg[e].back();
      hsum += p.size[static_cast<std::size_t>(nodes[k])];
    }
    ratio[e] =
        length / static_cast<double>(seg[e].size()) / (hsum / static_cast<double>(nodes.size()));
  }
  // An edge takes its spacing when all the edges of each of its faces have about the same ratio
  // (a face whose edges disagree would get a size varying inside).
  std::vector<char> agree(static_cast<std::size_t>(cad.num_faces()) + 1, 1);
  for (int f = 1; f <= cad.num_faces(); ++f) {
    double lo = 1e300, hi = 0;
    for (const CoEdge& ce : cad.coedges(f)) {
      const double r = ratio[static_cast<std::size_t>(ce.edge - 1)];
      if (r <= 0) continue;
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    agree[static_cast<std::size_t>(f)] = hi <= 1.05 * lo;
  }
  std::vector<double> out = p.size;
  std::vector<char> vertex_seen(p.size.size(), 0);
  for (std::size_t e = 0; e < ne; ++e) {
    if (seg[e].empty()) continue;
    bool eligible = true;
    for (int f : cad.faces_of_edge(static_cast<int>(e + 1)))
      eligible = eligible && agree[static_cast<std::size_t>(f)];
    if (!eligible) continue;
    const auto& nodes = p.node[e];
    const auto& sg = seg[e];
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const auto id = static_cast<std::size_t>(nodes[k]);
      if (p.node_edge[id] == 0) {  // a CAD vertex: its shortest segment over its edges
        const double s = k == 0 ? sg.front() : sg.back();
        if (!(s > 0)) continue;
        out[id] = std::min(p.size[id], vertex_seen[id] ? std::min(out[id], s) : s);
        vertex_seen[id] = 1;
      } else {
        out[id] = std::min(p.size[id], 0.5 * (sg[k - 1] + sg[k]));
      }
    }
  }
  p.size = out;
}

EdgePoints discretise_edges(const CadModel& cad, const SizeField& size) {
  std::vector<double> density(static_cast<std::size_t>(cad.num_edges()), 1.0);
  EdgePoints p;
  Bounds bounds;
  bounds.caps.resize(density.size());
  constexpr int kRounds = 8, kSizeRounds = 5;
  constexpr double kGradation = 0.5;
  // Narrow strips may ask for sizes far below the curvature floor (h / 20): a sliver of a face
  // 0.04 mm wide needs points about that close, whatever h is.
  const double narrow_floor = 0.3 * size.floor();
  const std::vector<SharpCorner> sharp = sharp_corners(cad, size, size.floor(), narrow_floor);
  bounds.zone = corner_zones(cad, sharp);
  std::size_t first_count = 0;
  for (int round = 0;; ++round) {
    build_points(cad, size, bounds, density, p);
    if (round == 0) first_count = p.xyz.size();
    std::vector<bool> refine(density.size(), false);
    int bad_face = 0;
    std::string where;
    for (int f = 1; f <= cad.num_faces(); ++f) {
      if (cad.solids_of_face(f).empty()) continue;
      const FaceBoundary b = face_boundary(cad, f, p);
      const auto crossings = crossing_segments(b);
      for (const auto& pair : crossings) {
        for (int s : pair) {
          for (int end : b.segments[static_cast<std::size_t>(s)]) {
            const int e =
                cad.coedges(f)[static_cast<std::size_t>(b.coedge[static_cast<std::size_t>(end)])]
                    .edge;
            refine[static_cast<std::size_t>(e - 1)] = true;
          }
        }
      }
      if (!crossings.empty() && bad_face == 0) {
        bad_face = f;
        const auto& seg = b.segments[static_cast<std::size_t>(crossings[0][0])];
        const auto& seg2 = b.segments[static_cast<std::size_t>(crossings[0][1])];
        const Vec2 at = b.uv[static_cast<std::size_t>(seg[0])];
        auto edge_of = [&](int pt) {
          return cad.coedges(f)[static_cast<std::size_t>(b.coedge[static_cast<std::size_t>(pt)])]
              .edge;
        };
        char msg[200];
        std::snprintf(msg, sizeof msg, " near (u, v) = (%.6g, %.6g), edges %d and %d", at[0], at[1],
                      edge_of(seg[0]), edge_of(seg2[0]));
        where = msg;
      }
    }
    // A boundary still crossing after its points grew 16-fold is malformed (pcurves off their
    // surface, a curve off its face), not under-resolved: stop before the doubling runs away
    // (and before graded_sizes, which costs up to n^2 on such edges: 50k points took 6 s).
    const bool runaway = p.xyz.size() > std::max<std::size_t>(16 * first_count, 20000);
    auto crossing_error = [&] {
      return Error("face " + std::to_string(bad_face) +
                   ": its boundary crosses itself in the parameter plane" + where);
    };
    if (bad_face != 0 && runaway) throw crossing_error();
    // Narrow faces get points no farther apart than they are wide, and every size grows by
    // at most half the distance from a smaller one; the next round's edges follow these.
    // The corner zones follow only the sizes of the field and the widths of strips (`other`,
    // from the field's sizes at the points, not the points' own: those already carry the
    // zone's neighbours' fine sizes).
    std::vector<double> other(p.size.size(), size.global());
    for (int v = 1; v <= cad.num_vertices(); ++v)
      other[static_cast<std::size_t>(v - 1)] = size.vertex_size(v);
    for (int e = 1; e <= cad.num_edges(); ++e) {
      const auto& ts = p.t[static_cast<std::size_t>(e - 1)];
      const auto& nodes = p.node[static_cast<std::size_t>(e - 1)];
      if (cad.edge_degenerate(e)) continue;
      for (std::size_t k = 0; k < ts.size(); ++k) {
        const double sk =
            ts.size() > 1 ? static_cast<double>(k) / static_cast<double>(ts.size() - 1) : 0.0;
        double& o = other[static_cast<std::size_t>(nodes[k])];
        o = std::min(o, size.edge_size(e, ts[k], sk));
      }
    }
    std::vector<double> target = p.size;
    narrow_face_sizes(cad, p, sharp, size.floor(), narrow_floor, other, target);
    short_segment_sizes(p, size.floor(), target);
    for (std::size_t i = 0; i < target.size(); ++i) target[i] = std::min(target[i], other[i]);
    const std::vector<double> graded = graded_sizes(p.xyz, target, size.global(), kGradation);
    const std::vector<double> graded_other = graded_sizes(p.xyz, other, size.global(), kGradation);
    const auto zone = corner_zones(cad, sharp, &p, &graded_other);
    bool finer = false;
    for (std::size_t i = 0; i < graded.size(); ++i) finer = finer || graded[i] < 0.8 * p.size[i];
    if (finer && round < kSizeRounds) {
      for (int e = 1; e <= cad.num_edges(); ++e) {
        const auto& ts = p.t[static_cast<std::size_t>(e - 1)];
        const auto& nodes = p.node[static_cast<std::size_t>(e - 1)];
        auto& c = bounds.caps[static_cast<std::size_t>(e - 1)];
        c.clear();
        // A zone's vertex is left out: its size (the zone's) is no bound beyond the zone.
        const auto& z = zone[static_cast<std::size_t>(e - 1)];
        for (std::size_t k = 0; k < ts.size(); ++k)
          if (!(k == 0 && z[0] > 0) && !(k + 1 == ts.size() && z[1] > 0))
            c.emplace_back(ts[k], graded[static_cast<std::size_t>(nodes[k])]);
        if (!c.empty() && c.front().first > c.back().first) std::reverse(c.begin(), c.end());
      }
      bounds.zone = zone;
    } else if (bad_face == 0) {
      return p;
    }
    if (bad_face == 0) continue;
    if (round == kRounds) throw crossing_error();
    for (std::size_t e = 0; e < density.size(); ++e)
      if (refine[e]) density[e] *= 2;
  }
}

}  // namespace hexfem
