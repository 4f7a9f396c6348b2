#include "mesher/edge_points.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mesher/mesh/error.hpp"
#include "mesher/rtree2d.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

namespace bgi = boost::geometry::index;
using BPoint = rt2::Point;
using BBox = rt2::Box;
using v3::norm;

// Parameters of the points on edge e: equal steps of the integral of 1/size over arc length,
// `density` times as many as the size field asks for.
std::vector<double> edge_parameters(const CadModel& cad, const SizeField& size, int e,
                                    double density) {
  const Vec2 range = cad.edge_range(e);
  if (cad.edge_degenerate(e)) return {range[0], range[1]};
  const double length = cad.edge_length(e);
  const int samples =
      static_cast<int>(std::clamp(std::ceil(6 * length / size.min_size()), 32.0, 20000.0));
  std::vector<double> ts(samples + 1), arc(samples + 1, 0.0), dens(samples + 1, 0.0);
  double max_kl = 0;
  for (int i = 0; i <= samples; ++i) ts[i] = range[0] + (range[1] - range[0]) * i / samples;
  for (int i = 1; i <= samples; ++i) {
    // Midpoint rule for the arc length of the sub-interval.
    const double tm = 0.5 * (ts[i - 1] + ts[i]);
    arc[i] = arc[i - 1] + norm(cad.edge_derivative(e, tm)) * (ts[i] - ts[i - 1]);
  }
  const double total = arc[samples] > 0 ? arc[samples] : 1.0;
  for (int i = 0; i <= samples; ++i) {
    dens[i] = 1.0 / size.edge_size(e, ts[i], arc[i] / total);
    if (i % 4 == 0) max_kl = std::max(max_kl, cad.edge_curvature(e, ts[i]) * length);
  }
  std::vector<double> integral(samples + 1, 0.0);
  for (int i = 1; i <= samples; ++i)
    integral[i] = integral[i - 1] + 0.5 * (dens[i] + dens[i - 1]) * (arc[i] - arc[i - 1]);
  const bool closed = cad.edge_closed(e);
  const bool curved = max_kl > 1e-3;
  const int min_segments = closed ? 3 : (curved ? 2 : 1);
  const int n = std::max(min_segments, static_cast<int>(std::lround(integral[samples] * density)));
  std::vector<double> out{range[0]};
  int j = 1;
  for (int k = 1; k < n; ++k) {
    const double target = integral[samples] * k / n;
    while (j < samples && integral[j] < target) ++j;
    const double span = integral[j] - integral[j - 1];
    const double w = span > 0 ? (target - integral[j - 1]) / span : 0.5;
    out.push_back(ts[j - 1] + w * (ts[j] - ts[j - 1]));
  }
  out.push_back(range[1]);
  return out;
}

void build_points(const CadModel& cad, const SizeField& size, const std::vector<double>& density,
                  EdgePoints& p) {
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
  for (int e = 1; e <= cad.num_edges(); ++e) {
    auto& ts = p.t[static_cast<std::size_t>(e - 1)];
    auto& nodes = p.node[static_cast<std::size_t>(e - 1)];
    ts = edge_parameters(cad, size, e, density[static_cast<std::size_t>(e - 1)]);
    const auto [v0, v1] = cad.edge_vertices(e);
    if (v0 <= 0 || v1 <= 0) throw Error("edge " + std::to_string(e) + " has no vertex at an end");
    const double length = cad.edge_length(e);
    for (std::size_t i = 0; i < ts.size(); ++i) {
      const bool first = i == 0, last = i + 1 == ts.size();
      const double s =
          ts.size() > 1 ? static_cast<double>(i) / static_cast<double>(ts.size() - 1) : 0.0;
      const double h = cad.edge_degenerate(e) ? size.vertex_size(v0) : size.edge_size(e, ts[i], s);
      if (first || last) {
        const int v = first ? v0 : v1;
        nodes.push_back(v - 1);
        p.size[static_cast<std::size_t>(v - 1)] =
            std::min(p.size[static_cast<std::size_t>(v - 1)], h);
        continue;
      }
      nodes.push_back(static_cast<int>(p.xyz.size()));
      p.xyz.push_back(cad.edge_point(e, ts[i]));
      p.size.push_back(h);
      p.node_edge.push_back(e);
    }
    (void)length;
  }
}

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
      // Where the next coedge does not start at this one's end in the parameter plane (a
      // defective pcurve, or a wire taken out of order), the end is kept as its own point.
      const std::size_t next = c + 1 < c1 ? c + 1 : c0;
      const auto& nts = p.t[static_cast<std::size_t>(ces[next].edge - 1)];
      const double tn = ces[next].reversed ? nts.back() : nts.front();
      const Vec2 end = cad.coedge_uv(f, ci, ts[index(n - 1)]);
      const Vec2 start = cad.coedge_uv(f, static_cast<int>(next), tn);
      if (std::hypot(end[0] - start[0], end[1] - start[1]) > gap_tol) {
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
  return b;
}

std::vector<std::array<int, 2>> crossing_segments(const FaceBoundary& b) {
  std::vector<std::pair<BBox, int>> boxes;
  boxes.reserve(b.segments.size());
  for (std::size_t s = 0; s < b.segments.size(); ++s) {
    const Vec2& a = b.uv[static_cast<std::size_t>(b.segments[s][0])];
    const Vec2& c = b.uv[static_cast<std::size_t>(b.segments[s][1])];
    boxes.emplace_back(BBox(BPoint(std::min(a[0], c[0]), std::min(a[1], c[1])),
                            BPoint(std::max(a[0], c[0]), std::max(a[1], c[1]))),
                       static_cast<int>(s));
  }
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
      if (sa[0] == sb[0] || sa[0] == sb[1] || sa[1] == sb[0] || sa[1] == sb[1]) continue;
      const Vec2 &p1 = b.uv[static_cast<std::size_t>(sa[0])],
                 &p2 = b.uv[static_cast<std::size_t>(sa[1])];
      const Vec2 &q1 = b.uv[static_cast<std::size_t>(sb[0])],
                 &q2 = b.uv[static_cast<std::size_t>(sb[1])];
      const double d1 = orient(p1, p2, q1), d2 = orient(p1, p2, q2);
      const double d3 = orient(q1, q2, p1), d4 = orient(q1, q2, p2);
      // Touching counts as crossing: a point on another segment would split a constraint.
      if (d1 * d2 <= 0 && d3 * d4 <= 0 && !(d1 == 0 && d2 == 0)) out.push_back({s, o});
    }
  }
  return out;
}

EdgePoints discretise_edges(const CadModel& cad, const SizeField& size) {
  std::vector<double> density(static_cast<std::size_t>(cad.num_edges()), 1.0);
  EdgePoints p;
  constexpr int kRounds = 6;
  for (int round = 0;; ++round) {
    build_points(cad, size, density, p);
    std::vector<bool> refine(density.size(), false);
    int bad_face = 0;
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
      if (!crossings.empty() && bad_face == 0) bad_face = f;
    }
    if (bad_face == 0) return p;
    if (round == kRounds)
      throw Error("face " + std::to_string(bad_face) +
                  ": its boundary crosses itself in the parameter plane at any refinement");
    for (std::size_t e = 0; e < density.size(); ++e)
      if (refine[e]) density[e] *= 2;
  }
}

}  // namespace hexfem
