#include "mesher/surface_points.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>
#include <string>

#include "mesher/mesh/error.hpp"
#include "mesher/rtree2d.hpp"
#include "mesher/splitmix.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

namespace bgi = boost::geometry::index;
using BPoint = rt2::Point;
using BBox = rt2::Box;
using Tree = rt2::PointTree;
using v3::dot;

// Parametric step whose image under the tangent map is the 3D tangent vector t (eq. 2).
bool parametric_step(const Frame& fr, const Vec3& t, Vec2& du) {
  const double m11 = dot(fr.t1, fr.t1), m12 = dot(fr.t1, fr.t2), m22 = dot(fr.t2, fr.t2);
  const double det = m11 * m22 - m12 * m12;
  if (!(det > 1e-300)) return false;
  const double r1 = dot(t, fr.t1), r2 = dot(t, fr.t2);
  du = {(m22 * r1 - m12 * r2) / det, (m11 * r2 - m12 * r1) / det};
  return std::isfinite(du[0]) && std::isfinite(du[1]);
}

// Oriented L∞ distance of y from the candidate c in c's frame (eq. 7, measured in 3D).
double linf(const Frame& c, const Vec3& y) {
  const Vec3 d{y[0] - c.p[0], y[1] - c.p[1], y[2] - c.p[2]};
  return std::max({std::abs(dot(d, c.d1)), std::abs(dot(d, c.d2)), std::abs(dot(d, c.n))});
}

}  // namespace

FacePoints pack_face(const CadModel& cad, const FaceField& field, const FaceBoundary& b,
                     const EdgePoints& points, const PackingOptions& opt) {
  const int f = field.face();
  const auto bounds = cad.uv_bounds(f);
  const double tol_u = 1e-9 * (bounds[1] - bounds[0]), tol_v = 1e-9 * (bounds[3] - bounds[2]);
  FacePoints out;
  std::vector<Vec2> uv;  // every point: boundary first, then interior
  std::vector<Vec3> xyz;
  std::deque<int> queue;
  std::vector<Vec3> singular;  // points of degenerate edges (poles, apexes): always checked
  Tree tree;
  const auto& ces = cad.coedges(f);
  for (std::size_t i = 0; i < b.uv.size(); ++i) {
    const int id = static_cast<int>(uv.size());
    uv.push_back(b.uv[i]);
    xyz.push_back(points.xyz[static_cast<std::size_t>(b.node[i])]);
    tree.insert({BPoint(b.uv[i][0], b.uv[i][1]), id});
    if (cad.edge_degenerate(ces[static_cast<std::size_t>(b.coedge[i])].edge)) {
      singular.push_back(xyz.back());
      continue;
    }
    queue.push_back(id);
  }

  // Boundary segments: a candidate closer than h/2 to one (3D distance to its chord) is
  // refused, so no point slips between boundary points spaced wider than the local size.
  const std::vector<std::pair<BBox, int>> seg_boxes = rt2::segment_boxes(b.uv, b.segments);
  const rt2::BoxTree seg_tree(seg_boxes.begin(), seg_boxes.end());
  std::vector<std::pair<BBox, int>> seg_hits;
  auto near_boundary = [&](const Vec3& x, const BBox& box, double limit) {
    seg_hits.clear();
    seg_tree.query(bgi::intersects(box), std::back_inserter(seg_hits));
    for (const auto& [sb, s] : seg_hits) {
      const auto& seg = b.segments[static_cast<std::size_t>(s)];
      const Vec3& p =
          points.xyz[static_cast<std::size_t>(b.node[static_cast<std::size_t>(seg[0])])];
      const Vec3& q =
          points.xyz[static_cast<std::size_t>(b.node[static_cast<std::size_t>(seg[1])])];
      const Vec3 pq = v3::sub(q, p), px = v3::sub(x, p);
      const double l2 = dot(pq, pq);
      const double w = l2 > 0 ? std::clamp(dot(px, pq) / l2, 0.0, 1.0) : 0.0;
      if (v3::norm(v3::sub(px, v3::scaled(pq, w))) < limit) return true;
    }
    return false;
  };

  std::vector<std::pair<BPoint, int>> hits;
  const double k = opt.k;
  // Whether a point at uc with frame fc keeps every other point out of its exclusion square of
  // half-side r (eq. 7), stays h/2 off the boundary segments and lies inside the trimmed face.
  auto free_at = [&](const Frame& fc, const Vec2& uc, double r) {
    Vec2 a, c;
    if (!parametric_step(fc, {fc.d1[0] * r, fc.d1[1] * r, fc.d1[2] * r}, a) ||
        !parametric_step(fc, {fc.d2[0] * r, fc.d2[1] * r, fc.d2[2] * r}, c))
      return false;
    // Box of the exclusion parallelogram, widened for the surface's curvature.
    const double ex = 1.5 * (std::abs(a[0]) + std::abs(c[0])),
                 ey = 1.5 * (std::abs(a[1]) + std::abs(c[1]));
    const BBox query(BPoint(uc[0] - ex, uc[1] - ey), BPoint(uc[0] + ex, uc[1] + ey));
    hits.clear();
    tree.query(bgi::intersects(query), std::back_inserter(hits));
    for (const auto& [pt, j] : hits)
      if (linf(fc, xyz[static_cast<std::size_t>(j)]) < r) return false;
    for (const Vec3& q : singular)
      if (linf(fc, q) < r) return false;
    return !near_boundary(fc.p, query, 0.5 * fc.h) && cad.contains(f, uc);
  };
  auto add_point = [&](const Vec2& uc, const Vec3& x) {
    const int id = static_cast<int>(uv.size());
    uv.push_back(uc);
    xyz.push_back(x);
    tree.insert({BPoint(uc[0], uc[1]), id});
    queue.push_back(id);
    out.uv.push_back(uc);
    out.xyz.push_back(x);
    if (opt.budget > 0 && out.uv.size() > opt.budget)
      throw Error("face " + std::to_string(f) + ": point packing exceeded its budget of " +
                  std::to_string(opt.budget) + " points (degenerate parametrisation?)");
  };
  // Seeds (the points of a face across a thin wall) go in first, under the same exclusion; the
  // fronts then grow from the boundary and from them.
  for (const Vec2& s : opt.seeds) {
    const Frame fc = field.frame(s);
    if (fc.ok && fc.h > 0 && free_at(fc, s, k * fc.h)) add_point(s, fc.p);
  }
  while (!queue.empty()) {
    const int i = queue.front();
    queue.pop_front();
    const Frame fr = field.frame(uv[static_cast<std::size_t>(i)]);
    if (!fr.ok || !(fr.h > 0)) continue;
    const Vec3 dirs[4] = {
        fr.d1, fr.d2, {-fr.d1[0], -fr.d1[1], -fr.d1[2]}, {-fr.d2[0], -fr.d2[1], -fr.d2[2]}};
    // Parametric extent of the spawning point's h-square, for the quick test below.
    Vec2 s1, s2;
    if (!parametric_step(fr, v3::scaled(fr.d1, fr.h), s1) ||
        !parametric_step(fr, v3::scaled(fr.d2, fr.h), s2))
      continue;
    const Vec2 box0{std::abs(s1[0]) + std::abs(s2[0]), std::abs(s1[1]) + std::abs(s2[1])};
    for (const Vec3& dir : dirs) {
      ++out.candidates;
      Vec2 du;
      if (!parametric_step(fr, {dir[0] * fr.h, dir[1] * fr.h, dir[2] * fr.h}, du)) continue;
      // Move along du until the chord from the spawning point is h long (the paper's
      // circle-surface intersection, with the tangent-plane guess as the start).
      const Vec2 u0 = uv[static_cast<std::size_t>(i)];
      Vec2 uc{u0[0] + du[0], u0[1] + du[1]};
      double s = 1;
      Vec3 x{};
      for (int it = 0; it < 4; ++it) {
        x = cad.point(f, uc);
        const double dist = v3::norm(v3::sub(x, fr.p));
        if (!(dist > 0) || std::abs(dist / fr.h - 1) < 1e-3 || it == 3) break;
        s *= std::clamp(fr.h / dist, 0.5, 2.0);
        uc = {u0[0] + s * du[0], u0[1] + s * du[1]};
      }
      if (!std::isfinite(uc[0]) || !std::isfinite(uc[1])) continue;
      if (uc[0] < bounds[0] - tol_u || uc[0] > bounds[1] + tol_u || uc[1] < bounds[2] - tol_v ||
          uc[1] > bounds[3] + tol_v)
        continue;
      // Most candidates land on a point already there: a cheap test in the spawning point's
      // frame first, with a square small enough to lie inside the candidate's own (its size
      // is at least half the spawning one's, its frame turned by any angle).
      {
        const double r0 = 0.35 * k * fr.h;
        const double ex = 1.5 * 0.35 * k * box0[0], ey = 1.5 * 0.35 * k * box0[1];
        hits.clear();
        tree.query(
            bgi::intersects(BBox(BPoint(uc[0] - ex, uc[1] - ey), BPoint(uc[0] + ex, uc[1] + ey))),
            std::back_inserter(hits));
        Frame centred = fr;
        centred.p = x;
        bool taken = false;
        for (const auto& [pt, j] : hits)
          if (linf(centred, xyz[static_cast<std::size_t>(j)]) < r0) {
            taken = true;
            break;
          }
        if (taken) continue;
      }
      const Frame fc = field.frame(uc);
      if (!fc.ok || !(fc.h > 0)) continue;
      // Where the size grows at the field's full gradation (0.5 per unit length: fc.h up to
      // 1.5 fr.h), k fc.h would exclude the candidate from its own spawning point, h away, and
      // no point would grow from a fine boundary into the face: a short boundary segment
      // would then face the coarse points across the face (a needle). The exclusion grows at
      // most by a quarter from the spawning point's.
      const double r = k * std::min(fc.h, 1.25 * fr.h);
      if (free_at(fc, uc, r)) add_point(uc, fc.p);
    }
  }
  return out;
}

std::vector<Vec2> opposite_seeds(const CadModel& cad, const FaceField& field,
                                 const std::vector<SeedCandidate>& candidates,
                                 double max_thickness) {
  const int f = field.face();
  const double cos_opposite = 0.9063;  // cos 25 deg
  FaceProjector projector(cad, f);
  std::vector<Vec2> seeds;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const SeedCandidate& c = candidates[i];
    Vec2 uv;
    if (!projector.project(c.p, c.start, uv) || !cad.contains(f, uv)) continue;
    const Frame fr = field.frame(uv);
    if (!fr.ok || !(fr.h > 0)) continue;
    const Vec3 d = v3::sub(c.p, fr.p);
    const double dist = v3::norm(d);
    if (dist < 0.3 * fr.h || dist > max_thickness * fr.h) continue;
    const Vec3 n = cad.normal(f, uv), ns = cad.normal(c.face, c.source_uv);
    if (dot(n, ns) > -cos_opposite || dot(d, n) > -cos_opposite * dist) continue;
    // Off the exact projection by h/20: four points in pairs straight across a planar wall are
    // coplanar, and TetGen may join them by a flat tet that no element absorbs (seen on
    // 40mm_capot). The direction turns from seed to seed: two pairs moved by the same vector
    // are a parallelogram, coplanar again (ANC101 at h = 2: three flat tets, the volume
    // pipeline run twice).
    Vec2 du;
    const double s = 0.05 * fr.h;
    const double angle = 2 * std::numbers::pi * splitmix_at(i);
    const double a = s * std::cos(angle), b = s * std::sin(angle);
    const Vec3 shift{a * fr.d1[0] + b * fr.d2[0], a * fr.d1[1] + b * fr.d2[1],
                     a * fr.d1[2] + b * fr.d2[2]};
    if (!parametric_step(fr, shift, du)) continue;
    seeds.push_back({uv[0] + du[0], uv[1] + du[1]});
  }
  return seeds;
}

}  // namespace hexfem
