#include "mesher/volume_points.hpp"

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using RPoint = bg::model::point<double, 3, bg::cs::cartesian>;
using RBox = bg::model::box<RPoint>;
using RValue = std::pair<RPoint, std::int32_t>;
using RTree = bgi::rtree<RValue, bgi::quadratic<16>>;

RPoint rp(const Vec3& p) {
  return RPoint(p[0], p[1], p[2]);
}

// The cloud so far: positions and an R-tree over them. A candidate's exclusion region is the
// cube of half-side k*h oriented by its frame; the R-tree is asked for its axis-aligned box.
class Cloud {
 public:
  explicit Cloud(const std::vector<Vec3>& surface_nodes) : points_(surface_nodes) {
    std::vector<RValue> values;
    values.reserve(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i)
      values.emplace_back(rp(points_[i]), static_cast<std::int32_t>(i));
    tree_ = RTree(values.begin(), values.end());
  }
  // True when an existing point x has max_i |F_i . (x - c)| < r.
  bool excluded(const Vec3& c, const Frame& f, double r) const {
    Vec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
      const double ext = r * (std::abs(f[0][a]) + std::abs(f[1][a]) + std::abs(f[2][a]));
      lo[a] = c[a] - ext;
      hi[a] = c[a] + ext;
    }
    for (auto it = tree_.qbegin(bgi::intersects(RBox(rp(lo), rp(hi)))); it != tree_.qend(); ++it) {
      const Vec3& x = points_[it->second];
      const Vec3 d{x[0] - c[0], x[1] - c[1], x[2] - c[2]};
      bool inside = true;
      for (int i = 0; i < 3 && inside; ++i)
        inside = std::abs(f[i][0] * d[0] + f[i][1] * d[1] + f[i][2] * d[2]) < r;
      if (inside) return true;
    }
    return false;
  }
  std::int32_t add(const Vec3& p) {
    const auto id = static_cast<std::int32_t>(points_.size());
    points_.push_back(p);
    tree_.insert(RValue(rp(p), id));
    return id;
  }
  const Vec3& point(std::int32_t i) const { return points_[i]; }
  std::size_t size() const { return points_.size(); }

 private:
  std::vector<Vec3> points_;
  RTree tree_;
};

struct Candidate {
  Vec3 pos;
  std::int32_t parent;
  double size = 0;         // the size there (FrameField3D::size_at)
  Frame frame{};           // the smooth field's, its front's or its nearest surface vertex's
  std::int32_t solid = 0;  // 0: rejected
};

// smooth: when given, every point's frame is the smooth field's at its position.
VolumePoints frontal(const SurfaceMesh& surface, const FrameField3D& field,
                     const SolidLocator& locator, double k, bool inherit_frame,
                     const SmoothFrameField* smooth) {
  const std::size_t ns = surface.mesh.nodes.size();
  Cloud cloud(surface.mesh.nodes);
  // Per cloud point: its size, its frame, and its solid (0 = surface).
  std::vector<double> size(ns);
  std::vector<std::int32_t> solid(ns, 0);
  std::vector<Frame> frame(ns);
  for (std::size_t v = 0; v < ns; ++v) {
    size[v] = field.vertex_size(static_cast<std::int32_t>(v));
    frame[v] = field.vertex_frame(static_cast<std::int32_t>(v));
  }
  // The nearest surface vertex is needed only for the paper's frame rule or for the size.
  const bool need_nearest_frame = !inherit_frame && !smooth;
  std::vector<std::int32_t> queue(ns);
  for (std::size_t v = 0; v < ns; ++v) queue[v] = static_cast<std::int32_t>(v);
  // A surface node that no triangle uses would grow points outside: skip it.
  std::vector<char> used(ns, 0);
  for (std::int32_t id : surface.mesh.bface_nodes)
    if (id >= 0) used[id] = 1;
  VolumePoints out;
  std::size_t head = 0;
  std::vector<Candidate> cands;
  // Batches of the FIFO: the candidates of a batch are tested in parallel against the cloud as
  // it was (tests that only reject more as the cloud grows), then accepted in FIFO order with a
  // final exclusion test. This gives exactly the sequential FIFO result.
  while (head < queue.size()) {
    const std::size_t end = std::min(queue.size(), head + 4096);
    cands.clear();
    for (std::size_t q = head; q < end; ++q) {
      const std::int32_t p = queue[q];
      if (static_cast<std::size_t>(p) < ns && !used[p]) continue;
      for (int j = 0; j < 6; ++j) cands.push_back({{0, 0, 0}, p});
    }
    const auto nc = static_cast<std::ptrdiff_t>(cands.size());
#pragma omp parallel for schedule(dynamic, 64)
    for (std::ptrdiff_t i = 0; i < nc; ++i) {
      Candidate& c = cands[i];
      const int j = static_cast<int>(i % 6);
      const Vec3& x = cloud.point(c.parent);
      const Frame& pf = frame[c.parent];
      const double hp = size[c.parent];
      const double sign = (j % 2) ? -1.0 : 1.0;
      const Vec3& dir = pf[j / 2];
      Vec3 trial;
      for (int a = 0; a < 3; ++a) trial[a] = x[a] + sign * hp * dir[a];
      // The nearest surface vertex is needed for the frame (--nearest-frame) or where a smaller
      // size may reach the trial point; elsewhere the size is the largest (same result, no
      // nearest-vertex query: most of this stage's time on a uniform size).
      double margin = 0;
      std::int32_t nv = -1;
      double hc = 0;
      auto size_and_nearest = [&] {
        if (!need_nearest_frame && field.at_max_size(trial)) {
          nv = -1;
          hc = field.max_size();
        } else {
          nv = field.nearest_vertex(trial, &margin);
          hc = field.size_at(trial, nv);
        }
      };
      size_and_nearest();
      const double d = 0.5 * (hp + hc);
      if (d != hp) {
        for (int a = 0; a < 3; ++a) trial[a] = x[a] + sign * d * dir[a];
        // A move shorter than the margin keeps the nearest vertex: no second query.
        if (nv >= 0 && std::abs(d - hp) < margin) {
          hc = field.size_at(trial, nv);
        } else {
          margin = 0;
          size_and_nearest();
        }
      }
      c.pos = trial;
      c.size = hc;
      c.frame = smooth          ? smooth->at(trial)
                : inherit_frame ? frame[c.parent]
                                : field.vertex_frame(nv);
      const double r = k * hc;
      if (cloud.excluded(trial, c.frame, r)) continue;
      if (solid[c.parent] > 0) {
        const int s = solid[c.parent];
        if (!locator.near_boundary(s, trial, r) && !locator.segment_hits_boundary(s, x, trial))
          c.solid = s;
      } else {
        for (int s : locator.solids_of_node(c.parent)) {
          if (!locator.near_boundary(s, trial, r) && locator.inside(s, trial)) {
            c.solid = s;
            break;
          }
        }
      }
    }
    const std::size_t before = cloud.size();
    for (const Candidate& c : cands) {
      ++out.candidates;
      if (c.solid == 0) continue;
      const double r = k * c.size;
      if (cloud.size() > before && cloud.excluded(c.pos, c.frame, r)) continue;
      const std::int32_t id = cloud.add(c.pos);
      size.push_back(c.size);
      frame.push_back(c.frame);
      solid.push_back(c.solid);
      queue.push_back(id);
      out.points.push_back(c.pos);
      out.solid.push_back(c.solid);
    }
    head = end;
  }
  return out;
}

// splitmix64: a portable generator (std distributions differ between standard libraries).
struct SplitMix {
  std::uint64_t s;
  double uniform() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return static_cast<double>(z >> 11) * 0x1.0p-53;
  }
};

// Random points, same tests (inside, off the boundary, oriented exclusion), until `target` are
// placed or the space is saturated.
VolumePoints random_points(const SurfaceMesh& surface, const FrameField3D& field,
                           const SolidLocator& locator, double k, std::size_t target,
                           std::uint64_t seed) {
  Vec3 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
          std::numeric_limits<double>::max()};
  Vec3 hi{-lo[0], -lo[1], -lo[2]};
  for (const Vec3& p : surface.mesh.nodes)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  Cloud cloud(surface.mesh.nodes);
  SplitMix rng{seed};
  VolumePoints out;
  std::size_t misses = 0;
  const std::size_t max_misses = 2000 + 20 * target;  // consecutive failures: saturated
  while (out.points.size() < target && misses < max_misses) {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = lo[a] + (hi[a] - lo[a]) * rng.uniform();
    ++out.candidates;
    ++misses;
    const std::int32_t nv = field.nearest_vertex(p);
    const double r = k * field.size_at(p, nv);
    if (cloud.excluded(p, field.vertex_frame(nv), r)) continue;
    const int s = locator.locate(p);
    if (s == 0 || locator.near_boundary(s, p, r)) continue;
    cloud.add(p);
    out.points.push_back(p);
    out.solid.push_back(s);
    misses = 0;
  }
  return out;
}

// Moves point i by up to `amount` (relative to its size) in a pseudo-random direction that
// depends only on i (deterministic).
void jitter_points(VolumePoints& vp, const FrameField3D& field, double amount) {
  if (amount <= 0) return;
  for (std::size_t i = 0; i < vp.points.size(); ++i) {
    SplitMix rng{0x5EED0000ull + i};
    const double h = field.size_at(vp.points[i], field.nearest_vertex(vp.points[i]));
    for (int a = 0; a < 3; ++a) vp.points[i][a] += amount * h * (2 * rng.uniform() - 1);
  }
}

}  // namespace

VolumePoints insert_volume_points(const SurfaceMesh& surface, const FrameField3D& field,
                                  const SolidLocator& locator, const VolumePointsOptions& options) {
  if (!(options.k > 0 && options.k < 1))
    throw Error("volume points: k must be in (0, 1), got " + std::to_string(options.k));
  if (!(options.jitter >= 0 && options.jitter < 0.01))
    throw Error("volume points: jitter must be in [0, 0.01), got " +
                std::to_string(options.jitter));
  std::unique_ptr<SmoothFrameField> smooth;
  if (options.smooth_frame)
    smooth = std::make_unique<SmoothFrameField>(surface, field, locator, options.smooth);
  if (!options.random) {
    VolumePoints out =
        frontal(surface, field, locator, options.k, options.inherit_frame, smooth.get());
    jitter_points(out, field, options.jitter);
    return out;
  }
  std::size_t target = options.random_count;
  std::size_t frontal_count = 0;
  if (target == 0) {
    frontal_count = frontal(surface, field, locator, options.k, options.inherit_frame, smooth.get())
                        .points.size();
    target = frontal_count;
  }
  VolumePoints out = random_points(surface, field, locator, options.k, target, options.seed);
  out.frontal_count = frontal_count;
  jitter_points(out, field, options.jitter);
  return out;
}

}  // namespace hexfem
