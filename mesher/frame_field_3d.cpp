#include "mesher/frame_field_3d.hpp"

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "mesher/mesh/error.hpp"
#include "mesher/point_grid.hpp"

namespace hexfem {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using RPoint = bg::model::point<double, 3, bg::cs::cartesian>;
using RValue = std::pair<RPoint, std::int32_t>;
using RBox = bg::model::box<RPoint>;
using RReach = std::pair<RBox, std::int32_t>;  // a smaller vertex and the box it lowers the size in

namespace {

// How far from a vertex of size s the size stays below the largest, (largest - s) / grading, with
// some slack: at_max_size then decides with size_at's own arithmetic.
double lowering_reach(double s, double largest) {
  return (largest - s) / FrameField3D::kSizeGrading * (1 + 1e-6) + 1e-12 * largest;
}

}  // namespace

struct FrameField3D::Index {
  bgi::rtree<RValue, bgi::rstar<16>> tree;
  // The vertices whose size is below the largest, each as the box (L-infinity) beyond which it
  // leaves the size at the largest: a point queries only the vertices that may lower its size.
  // (One box of the widest reach around the point, as before, held many that cannot: the
  // bottle at h = 0.18 took 17.7 s for its volume points instead of 11.1 s, the same points.)
  bgi::rtree<RReach, bgi::rstar<16>> smaller;
  // A grid of cells over the surface's box: far[c] when no smaller vertex lies within reach of
  // any point of cell c (L-infinity), so that at_max_size is true there with no query. Most of a
  // part is such cells; the frontal insertion asks about ten million times.
  CellLayout cells;
  std::vector<char> far;
  void build_far(const std::vector<Vec3>& nodes, const std::vector<double>& sizes, double max_size);
};

void FrameField3D::Index::build_far(const std::vector<Vec3>& nodes,
                                    const std::vector<double>& sizes, double max_size) {
  // Cells of about the largest size, at most 2^22 of them.
  cells = CellLayout::around(nodes, max_size, std::size_t{1} << 22);
  const std::int64_t* n = cells.n;
  const std::size_t total = cells.size();
  // A vertex v of size s_v lowers the size only within r_v = (max - s_v) / kSizeGrading of it.
  // A point of cell c and v in cell j are more than r_v apart along axis a when
  // (|c_a - j_a| - 1) side > r_v: so v reaches only the cells within m_v = floor(r_v / side) + 1
  // of its own along every axis. The vertices of each m (m_v <= reach / side + 1, a handful of
  // values) mark their cells, grown by m along each axis in turn.
  std::vector<std::vector<std::size_t>> by_m;
  for (std::size_t v = 0; v < nodes.size(); ++v) {
    if (!(sizes[v] < max_size)) continue;
    const std::int64_t c = cells.cell_inside(nodes[v]);
    if (c < 0) continue;
    const double r = lowering_reach(sizes[v], max_size);
    const auto m = static_cast<std::size_t>(std::min(r * cells.inv_side, 1e6)) + 1;
    if (by_m.size() <= m) by_m.resize(m + 1);
    by_m[m].push_back(static_cast<std::size_t>(c));
  }
  const std::int64_t stride[3] = {1, n[0], n[0] * n[1]};
  std::vector<char> any_near(total, 0), near(total), grown(total);
  for (std::size_t mm = 1; mm < by_m.size(); ++mm) {
    if (by_m[mm].empty()) continue;
    const auto m = static_cast<std::int64_t>(mm);
    std::fill(near.begin(), near.end(), 0);
    for (std::size_t c : by_m[mm]) near[c] = 1;
    for (int a = 0; a < 3; ++a) {
      // Along axis a: a running count of marked cells within m of each cell.
      for (std::size_t c0 = 0; c0 < total; ++c0) {
        if ((static_cast<std::int64_t>(c0) / stride[a]) % n[a] != 0) continue;  // line starts
        std::int64_t count = 0;
        for (std::int64_t i = 0; i < std::min(m, n[a]); ++i) count += near[c0 + i * stride[a]];
        for (std::int64_t i = 0; i < n[a]; ++i) {
          if (i + m < n[a]) count += near[c0 + (i + m) * stride[a]];
          if (i - m - 1 >= 0) count -= near[c0 + (i - m - 1) * stride[a]];
          grown[c0 + i * stride[a]] = count > 0;
        }
      }
      near.swap(grown);
    }
    for (std::size_t c = 0; c < total; ++c) any_near[c] |= near[c];
  }
  far.resize(total);
  for (std::size_t c = 0; c < total; ++c) far[c] = !any_near[c];
}

namespace {

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

bool normalize(Vec3& a) {
  const double n = std::sqrt(dot(a, a));
  if (!(n > 1e-12)) return false;
  for (double& x : a) x /= n;
  return true;
}

}  // namespace

FrameField3D::FrameField3D(const SurfaceMesh& surface) : index_(std::make_unique<Index>()) {
  const std::size_t n = surface.mesh.nodes.size();
  if (surface.frame.size() != n || surface.size.size() != n)
    throw Error("surface mesh: " + std::to_string(n) + " nodes but " +
                std::to_string(surface.frame.size()) + " frames and " +
                std::to_string(surface.size.size()) + " sizes");
  if (n == 0) throw Error("surface mesh has no nodes");
  frames_.resize(n);
  sizes_ = surface.size;
  nodes_ = surface.mesh.nodes;
  std::vector<RValue> values;
  values.reserve(n);
  for (std::size_t v = 0; v < n; ++v) {
    if (!(sizes_[v] > 0) || !std::isfinite(sizes_[v]))
      throw Error("surface mesh: node " + std::to_string(v) + " has size " +
                  std::to_string(sizes_[v]));
    Vec3 d1 = surface.frame[v][0], nn = surface.frame[v][2];
    bool ok = normalize(nn);
    const double t = dot(d1, nn);
    for (int i = 0; i < 3; ++i) d1[i] -= t * nn[i];
    ok = ok && normalize(d1);
    if (!ok) throw Error("surface mesh: node " + std::to_string(v) + " has a degenerate frame");
    const Vec3 d2{nn[1] * d1[2] - nn[2] * d1[1], nn[2] * d1[0] - nn[0] * d1[2],
                  nn[0] * d1[1] - nn[1] * d1[0]};
    frames_[v] = {d1, d2, nn};
    max_size_ = std::max(max_size_, sizes_[v]);
    const Vec3& p = surface.mesh.nodes[v];
    values.emplace_back(RPoint(p[0], p[1], p[2]), static_cast<std::int32_t>(v));
  }
  // The packing constructor builds the same tree for the same input (deterministic queries).
  index_->tree = bgi::rtree<RValue, bgi::rstar<16>>(values.begin(), values.end());
  std::vector<RReach> smaller;
  for (std::size_t v = 0; v < n; ++v)
    if (sizes_[v] < max_size_) {
      const double r = lowering_reach(sizes_[v], max_size_);
      const Vec3& x = nodes_[v];
      smaller.emplace_back(
          RBox(RPoint(x[0] - r, x[1] - r, x[2] - r), RPoint(x[0] + r, x[1] + r, x[2] + r)),
          static_cast<std::int32_t>(v));
    }
  index_->smaller = bgi::rtree<RReach, bgi::rstar<16>>(smaller.begin(), smaller.end());
  index_->build_far(nodes_, sizes_, max_size_);
}

bool FrameField3D::at_max_size(const Vec3& p) const {
  if (index_->smaller.empty()) return true;
  const std::int64_t c = index_->cells.cell_inside(p);
  if (c >= 0 && index_->far[static_cast<std::size_t>(c)]) return true;
  const RPoint q(p[0], p[1], p[2]);
  for (auto it = index_->smaller.qbegin(bgi::intersects(q)); it != index_->smaller.qend(); ++it)
    if (size_at(p, it->second) < max_size_) return false;
  return true;
}

FrameField3D::~FrameField3D() = default;

double FrameField3D::size_at(const Vec3& p, std::int32_t v) const {
  const Vec3& x = nodes_[v];
  const Vec3 d{p[0] - x[0], p[1] - x[1], p[2] - x[2]};
  return std::min(max_size_, sizes_[v] + kSizeGrading * std::sqrt(dot(d, d)));
}

std::int32_t FrameField3D::nearest_vertex(const Vec3& p, double* margin) const {
  std::int32_t best = -1;
  double d2[2] = {0, std::numeric_limits<double>::infinity()};
  // Ask for two so that an exact tie is broken by the lower index, not by the tree layout. The
  // one-shot query is much cheaper than the incremental iterator (qbegin).
  RValue two[2];
  const std::size_t n = index_->tree.query(bgi::nearest(RPoint(p[0], p[1], p[2]), 2), two);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = bg::comparable_distance(two[i].first, RPoint(p[0], p[1], p[2]));
    if (best < 0 || d < d2[0] || (d == d2[0] && two[i].second < best)) {
      if (best >= 0) d2[1] = d2[0];
      best = two[i].second;
      d2[0] = d;
    } else {
      d2[1] = std::min(d2[1], d);
    }
  }
  if (margin) *margin = 0.5 * (std::sqrt(d2[1]) - std::sqrt(d2[0]));
  return best;
}

}  // namespace hexfem
