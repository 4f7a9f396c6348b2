#include "mesher/volume_points.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <utility>

#include "mesher/mesh/error.hpp"
#include "mesher/point_grid.hpp"
#include "mesher/splitmix.hpp"
#include "mesher/vec3.hpp"

namespace hexfem {

namespace {

// The axis-aligned box [lo, hi] around the cube of half-side r about c oriented by frame f.
void frame_box(const Vec3& c, const Frame& f, double r, Vec3& lo, Vec3& hi) {
  for (int a = 0; a < 3; ++a) {
    const double ext = r * (std::abs(f[0][a]) + std::abs(f[1][a]) + std::abs(f[2][a]));
    lo[a] = c[a] - ext;
    hi[a] = c[a] + ext;
  }
}

// The cloud's cell side for queries of boxes about box_per_size * s wide around points of size
// s, the sizes drawn from `sizes`: the side, among a few fractions of the largest size, that
// visits the fewest cells and points in all. A graded part (small sizes on thin blades, the
// largest in a hub) wants small cells; a uniform one cells of about its size.
double cell_side(const std::vector<double>& sizes, double box_per_size) {
  const double largest = sizes.empty() ? 1 : *std::max_element(sizes.begin(), sizes.end());
  const std::size_t step = std::max<std::size_t>(1, sizes.size() / 20000);
  double best = largest, best_cost = std::numeric_limits<double>::infinity();
  for (double f = 2; f > 0.05; f /= std::sqrt(2.0)) {
    const double c = f * largest;
    double cost = 0;
    for (std::size_t i = 0; i < sizes.size(); i += step) {
      const double s = sizes[i];
      const double cells = std::pow(box_per_size * s / c + 1, 3);
      cost += cells * (1 + std::pow(c / s, 3));  // a cell visited, and the points it holds
    }
    if (cost < best_cost) {
      best_cost = cost;
      best = c;
    }
  }
  return best;
}

// The cloud so far: positions in a grid of cells (point_grid.hpp). A candidate's exclusion
// region is the cube of half-side k*h oriented by its frame; the grid is asked for its
// axis-aligned box, and the points in that box are tested.
class Cloud {
 public:
  // cell: the grid's cell side (cell_side).
  // The interior points fall inside the surface's box: a grid over the points given.
  Cloud(const std::vector<Vec3>& points, double cell)
      : points_(points), grid_(CellLayout::around(points, cell, std::size_t{1} << 23)) {
    for (std::size_t i = 0; i < points_.size(); ++i)
      grid_.insert(static_cast<std::int32_t>(i), points_[i]);
  }
  // True when an existing point x has max_i |F_i . (x - c)| < r.
  bool excluded(const Vec3& c, const Frame& f, double r) const {
    return excluded_other(c, f, r, -1);
  }
  // The same test, ignoring point `self` (-1: none).
  bool excluded_other(const Vec3& c, const Frame& f, double r, std::int32_t self) const {
    Vec3 lo, hi;
    frame_box(c, f, r, lo, hi);
    bool found = false;
    for_each_in_box_until(lo, hi, [&](std::int32_t id) {
      if (id == self) return false;
      const Vec3& x = points_[id];
      const Vec3 d{x[0] - c[0], x[1] - c[1], x[2] - c[2]};
      bool inside = true;
      for (int i = 0; i < 3 && inside; ++i)
        inside = std::abs(f[i][0] * d[0] + f[i][1] * d[1] + f[i][2] * d[2]) < r;
      found = inside;
      return inside;
    });
    return found;
  }
  // Point i moves to p.
  void move(std::int32_t i, const Vec3& p) {
    grid_.remove(i, points_[i]);
    points_[i] = p;
    grid_.insert(i, p);
  }
  std::int32_t add(const Vec3& p) {
    const auto id = static_cast<std::int32_t>(points_.size());
    points_.push_back(p);
    grid_.insert(id, p);
    return id;
  }
  const Vec3& point(std::int32_t i) const { return points_[i]; }
  const std::vector<Vec3>& points() const { return points_; }
  std::size_t size() const { return points_.size(); }
  // Calls f(id) for every point in the closed axis-aligned box [lo, hi].
  template <class F>
  void for_each_in_box(const Vec3& lo, const Vec3& hi, F&& f) const {
    for_each_in_box_until(lo, hi, [&](std::int32_t id) {
      f(id);
      return false;
    });
  }

 private:
  // The same, until f returns true.
  template <class F>
  void for_each_in_box_until(const Vec3& lo, const Vec3& hi, F&& f) const {
    grid_.for_each_near(lo, hi, [&](std::int32_t id) {
      const Vec3& x = points_[id];
      if (x[0] < lo[0] || x[0] > hi[0] || x[1] < lo[1] || x[1] > hi[1] || x[2] < lo[2] ||
          x[2] > hi[2])
        return false;
      return f(id);
    });
  }
  std::vector<Vec3> points_;
  PointGrid grid_;
};

// Lattice relaxation of the interior points (--relax-points N). Each interior point finds its
// six lattice neighbours: the point nearest to x +- h d_i in its frame's L-infinity distance,
// within kRelaxTolerance h. Jacobi sweeps then move it towards the mean of what its neighbours
// imply: the midpoint of the two neighbours of an axis that has both (so a stretched or sheared
// seam where two fronts met spreads over the layers around it), and, along an axis with one
// neighbour only, the neighbour's offset across that axis (tangential alignment, spacing kept).
// The neighbours are found once (found again every few sweeps, points collapsed onto each
// other). Surface points stay. A point that would end within k h of the boundary, or across it,
// keeps its place.
constexpr double kRelaxTolerance = 0.45;  // a neighbour within 0.45 h of x +- h d_i
constexpr double kRelaxStep = 0.5;        // Jacobi damping

std::vector<std::array<std::int32_t, 6>> lattice_neighbours(const std::vector<Vec3>& x,
                                                            std::size_t ns,
                                                            const std::vector<Frame>& frame,
                                                            const std::vector<double>& size,
                                                            double tol) {
  const Cloud cloud(x, cell_side(size, 2 * std::sqrt(3.0) * (1 + tol)));
  const std::size_t ni = x.size() - ns;
  std::vector<std::array<std::int32_t, 6>> nb(ni);
  const auto nni = static_cast<std::ptrdiff_t>(ni);
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t i = 0; i < nni; ++i) {
    const auto p = static_cast<std::int32_t>(ns + i);
    const Vec3& c = x[p];
    const Frame& f = frame[p];
    const double h = size[p];
    std::array<double, 6> best;
    best.fill(tol);
    nb[i].fill(-1);
    Vec3 lo, hi;
    frame_box(c, f, (1 + tol) * h, lo, hi);
    cloud.for_each_in_box(lo, hi, [&](std::int32_t q) {
      if (q == p) return;
      const Vec3& y = x[q];
      const Vec3 d{y[0] - c[0], y[1] - c[1], y[2] - c[2]};
      std::array<double, 3> u;
      for (int a = 0; a < 3; ++a) u[a] = (f[a][0] * d[0] + f[a][1] * d[1] + f[a][2] * d[2]) / h;
      for (int a = 0; a < 3; ++a) {
        const double s = u[a] > 0 ? 1.0 : -1.0;
        const double err =
            std::max({std::abs(u[a] - s), std::abs(u[(a + 1) % 3]), std::abs(u[(a + 2) % 3])});
        const int slot = 2 * a + (s > 0 ? 0 : 1);
        if (err < best[slot] || (err == best[slot] && q < nb[i][slot])) {
          best[slot] = err;
          nb[i][slot] = q;
        }
      }
    });
  }
  return nb;
}

std::size_t keep_valid_moves(std::vector<Vec3>& cur, std::size_t ns,
                             const std::vector<Frame>& frame, const std::vector<double>& size,
                             const std::vector<std::int32_t>& solid, const SolidLocator& locator,
                             double k, VolumePoints& out);

// all: the surface points, then out.points (the frontal order).
void relax_lattice(const std::vector<Vec3>& all, std::size_t ns, const std::vector<Frame>& frame,
                   const std::vector<double>& size, const std::vector<std::int32_t>& solid,
                   const SolidLocator& locator, double k, int iterations, VolumePoints& out) {
  const std::size_t ni = out.points.size();
  if (iterations <= 0 || ni == 0) return;
  std::vector<Vec3> cur = all;
  const auto nni = static_cast<std::ptrdiff_t>(ni);
  const std::vector<std::array<std::int32_t, 6>> nb =
      lattice_neighbours(cur, ns, frame, size, kRelaxTolerance);
  std::vector<Vec3> next;
  for (int it = 0; it < iterations; ++it) {
    next = cur;
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < nni; ++i) {
      const std::size_t p = ns + i;
      const Frame& f = frame[p];
      Vec3 acc{0, 0, 0};
      int cnt = 0;
      for (int a = 0; a < 3; ++a) {
        const std::int32_t qp = nb[i][2 * a], qm = nb[i][2 * a + 1];
        Vec3 delta;
        if (qp >= 0 && qm >= 0) {
          for (int c = 0; c < 3; ++c) delta[c] = 0.5 * (cur[qp][c] + cur[qm][c]) - cur[p][c];
        } else if (qp >= 0 || qm >= 0) {
          const std::int32_t q = qp >= 0 ? qp : qm;
          const double s = qp >= 0 ? 1.0 : -1.0;
          const double h = 0.5 * (size[p] + size[q]);
          for (int c = 0; c < 3; ++c) delta[c] = cur[q][c] - s * h * f[a][c] - cur[p][c];
          const double along = delta[0] * f[a][0] + delta[1] * f[a][1] + delta[2] * f[a][2];
          for (int c = 0; c < 3; ++c) delta[c] -= along * f[a][c];
        } else {
          continue;
        }
        for (int c = 0; c < 3; ++c) acc[c] += delta[c];
        ++cnt;
      }
      if (cnt == 0) continue;
      for (int c = 0; c < 3; ++c) next[p][c] = cur[p][c] + kRelaxStep * acc[c] / cnt;
    }
    std::swap(cur, next);
  }
  keep_valid_moves(cur, ns, frame, size, solid, locator, k, out);
}

// cur: the surface points, then the interior points' new places (out.points: their old ones).
// Each interior point takes its new place when that is valid; else it keeps its old one.
std::size_t keep_valid_moves(std::vector<Vec3>& cur, std::size_t ns,
                             const std::vector<Frame>& frame, const std::vector<double>& size,
                             const std::vector<std::int32_t>& solid, const SolidLocator& locator,
                             double k, VolumePoints& out) {
  const std::size_t ni = out.points.size();
  const auto nni = static_cast<std::ptrdiff_t>(ni);
  // Each point's move is kept when it stays inside and at least k h from the boundary. (Moves
  // capped at h/2 or h kept fewer hexes: the gains come from points that travel further.)
  std::vector<char> moved(ni, 0);
#pragma omp parallel for schedule(dynamic, 256)
  for (std::ptrdiff_t i = 0; i < nni; ++i) {
    const std::size_t p = ns + i;
    const Vec3& from = out.points[i];
    const Vec3& to = cur[p];
    const int s = solid[p];
    moved[i] =
        !locator.near_boundary(s, to, k * size[p]) && !locator.segment_hits_boundary(s, from, to);
  }
  // No two points closer than k h / 2 in a frame's L-infinity distance (the insertion kept k h):
  // moved points in such a pair go back, until none is left. The insertion's own points keep
  // k h between them, so every point back is always a valid end: it is taken after 8 rounds.
  // After the first round only the moved points next to one sent back can be new pairs: they
  // are checked again, in the cloud with those points moved back (a million points: 0.6 s less
  // than checking every point in a new cloud each round; the same points go back).
  for (std::ptrdiff_t i = 0; i < nni; ++i) cur[ns + i] = moved[i] ? cur[ns + i] : out.points[i];
  Cloud cloud(cur, cell_side(size, std::sqrt(3.0) * k));
  double reach = 0;  // an exclusion cube's half-diagonal, the largest
  for (std::size_t i = 0; i < ni; ++i) reach = std::max(reach, 0.5 * k * size[ns + i]);
  reach *= std::sqrt(3.0);
  std::vector<std::int32_t> check, sent;
  for (std::size_t i = 0; i < ni; ++i)
    if (moved[i]) check.push_back(static_cast<std::int32_t>(i));
  std::vector<char> marked(ni, 0);
  for (int round = 0;; ++round) {
    if (round == 8) {
      moved.assign(ni, 0);
      break;
    }
    const auto nc = static_cast<std::ptrdiff_t>(check.size());
    std::vector<char> back(check.size(), 0);
#pragma omp parallel for schedule(dynamic, 256)
    for (std::ptrdiff_t c = 0; c < nc; ++c) {
      const std::size_t p = ns + check[c];
      back[c] =
          cloud.excluded_other(cur[p], frame[p], 0.5 * k * size[p], static_cast<std::int32_t>(p));
    }
    sent.clear();
    for (std::ptrdiff_t c = 0; c < nc; ++c)
      if (back[c]) {
        moved[check[c]] = 0;
        sent.push_back(check[c]);
      }
    if (sent.empty()) break;
    for (std::int32_t i : sent) {
      cur[ns + i] = out.points[i];
      cloud.move(static_cast<std::int32_t>(ns + i), out.points[i]);
    }
    check.clear();
    for (std::int32_t i : sent) {
      const Vec3& c = out.points[i];
      cloud.for_each_in_box({c[0] - reach, c[1] - reach, c[2] - reach},
                            {c[0] + reach, c[1] + reach, c[2] + reach}, [&](std::int32_t q) {
                              if (q < static_cast<std::int32_t>(ns)) return;
                              const std::int32_t j = q - static_cast<std::int32_t>(ns);
                              if (moved[j] && !marked[j]) {
                                marked[j] = 1;
                                check.push_back(j);
                              }
                            });
    }
    for (std::int32_t j : check) marked[j] = 0;
    std::sort(check.begin(), check.end());
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < ni; ++i)
    if (moved[i]) {
      out.points[i] = cur[ns + i];
      ++kept;
    }
  return kept;
}

// Points that close the surface points' Voronoi cells for the Lp-CVT: each surface vertex of
// one solid, moved out by its size along its outward normal (the area-weighted mean of its
// triangles'). A vertex between two solids gets none: the other solid's points close its cell.
std::vector<Vec3> ghost_points(const SurfaceMesh& surface, const SolidLocator& locator,
                               const std::vector<double>& size) {
  const auto& X = surface.mesh.nodes;
  std::vector<Vec3> normal(X.size(), {0, 0, 0});
  const auto& T = surface.mesh.bface_nodes;
  for (std::size_t t = 0; t + 3 < T.size(); t += 4) {
    const Vec3 n = v3::cross(v3::sub(X[T[t + 1]], X[T[t]]), v3::sub(X[T[t + 2]], X[T[t]]));
    for (int a = 0; a < 3; ++a) normal[T[t + a]] = v3::add(normal[T[t + a]], n);
  }
  std::vector<Vec3> ghosts;
  for (std::size_t v = 0; v < X.size(); ++v) {
    const double len = v3::norm(normal[v]);
    if (len == 0 || locator.solids_of_node(v).size() != 1) continue;
    ghosts.push_back(v3::add(X[v], v3::scaled(normal[v], size[v] / len)));
  }
  return ghosts;
}

// Two surface frames closer than this (up to the cube's symmetries) count as the same.
constexpr double kSameFrame = std::numbers::pi / 180;  // 1 degree
// Frames compared at most (a part of many differently turned planar walls): the rest do not lead.
constexpr std::size_t kMaxFrames = 256;

// The axis of f closest to the direction n.
int axis_along(const Frame& f, const Vec3& n) {
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(v3::dot(f[i], n)) > std::abs(v3::dot(f[best], n))) best = i;
  return best;
}

// The surface nodes whose fronts lead (VolumePointsOptions::coherent_first):
//  - the frame field does not turn there: every node sharing a triangle with one has its frame
//    within kSameFrame. That is a planar wall away from holes, not a curved face (its normal
//    turns) nor a planar face near a hole (its cross field turns there);
//  - and that frame is shared by walls facing at least `walls.min_axes` of its axes, holding
//    `walls.min_share` of the surface nodes: box-like walls that one lattice fits, not the two
//    sides of a plate (one axis) nor a few flats on a curved part (their lattice would flood
//    what curved walls bound). Every such frame leads at once (CoherentWalls).
std::vector<char> leading_nodes(const MixedMesh& m, const std::vector<Frame>& frame,
                                const CoherentWalls& walls) {
  const std::size_t n = m.nodes.size();
  std::vector<char> steady(n, 1);  // the frame does not turn there
  for (std::size_t t = 0; t < m.num_bfaces(); ++t)
    for (int i = 0; i < 3; ++i) {
      const std::int32_t a = m.bface_nodes[4 * t + i], b = m.bface_nodes[4 * t + (i + 1) % 3];
      if (frame_angle(frame[a], frame[b]) > kSameFrame) steady[a] = steady[b] = 0;
    }
  // The frames of those nodes, each with the axes its walls face and its number of nodes.
  std::vector<Frame> frames;
  std::vector<unsigned> axes;
  std::vector<std::size_t> members;
  std::vector<std::int32_t> which(n, -1);
  for (std::size_t v = 0; v < n; ++v) {
    if (!steady[v]) continue;
    std::size_t c = 0;
    while (c < frames.size() && frame_angle(frames[c], frame[v]) > kSameFrame) ++c;
    if (c == frames.size()) {
      if (frames.size() == kMaxFrames) continue;
      frames.push_back(frame[v]);
      axes.push_back(0);
      members.push_back(0);
    }
    which[v] = static_cast<std::int32_t>(c);
    axes[c] |= 1u << axis_along(frames[c], frame[v][2]);  // frame[v][2]: the normal
    ++members[c];
  }
  std::vector<char> lead(n, 0);
  for (std::size_t v = 0; v < n; ++v)
    lead[v] = which[v] >= 0 && std::popcount(axes[which[v]]) >= walls.min_axes &&
              static_cast<double>(members[which[v]]) >= walls.min_share * static_cast<double>(n);
  return lead;
}

struct Candidate {
  Vec3 pos;
  std::int32_t parent;
  double size = 0;         // the size there (FrameField3D::size_at)
  Frame frame{};           // the smooth field's, its front's or its nearest surface vertex's
  std::int32_t solid = 0;  // 0: rejected
};

// smooth: when given, every point's frame is the smooth field's at its position.
// coherent: VolumePointsOptions::coherent_first's walls, or null (every front at once).
VolumePoints frontal(const SurfaceMesh& surface, const FrameField3D& field,
                     const SolidLocator& locator, double k, bool inherit_frame,
                     const SmoothFrameField* smooth, const CoherentWalls* coherent,
                     int relax_iterations, const LpCvtOptions& lpcvt) {
  const std::size_t ns = surface.mesh.nodes.size();
  // Per cloud point: its size, its frame, and its solid (0 = surface).
  std::vector<double> size(ns);
  std::vector<std::int32_t> solid(ns, 0);
  std::vector<Frame> frame(ns);
  for (std::size_t v = 0; v < ns; ++v) {
    size[v] = field.vertex_size(static_cast<std::int32_t>(v));
    frame[v] = field.vertex_frame(static_cast<std::int32_t>(v));
  }
  Cloud cloud(surface.mesh.nodes, cell_side(size, 2 * std::sqrt(3.0) * k));
  // The nearest surface vertex is needed only for the paper's frame rule or for the size.
  const bool need_nearest_frame = !inherit_frame && !smooth;
  // The FIFO starts from the leading surface nodes alone when asked, and takes the others when
  // it runs empty.
  std::vector<std::int32_t> queue, later;
  const std::vector<char> first =
      coherent ? leading_nodes(surface.mesh, frame, *coherent) : std::vector<char>(ns, 1);
  for (std::size_t v = 0; v < ns; ++v)
    (first[v] ? queue : later).push_back(static_cast<std::int32_t>(v));
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
  while (head < queue.size() || !later.empty()) {
    if (head == queue.size()) {
      queue.insert(queue.end(), later.begin(), later.end());
      later.clear();
    }
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
  relax_lattice(cloud.points(), ns, frame, size, solid, locator, k, relax_iterations, out);
  if (lpcvt.iterations > 0 && !out.points.empty()) {
    std::vector<Vec3> all = cloud.points();
    for (std::size_t i = 0; i < out.points.size(); ++i) all[ns + i] = out.points[i];
    const std::vector<Vec3> ghosts = ghost_points(surface, locator, size);
    all.insert(all.end(), ghosts.begin(), ghosts.end());
    const std::vector<Vec3> moved =
        optimize_lp_cvt(all, ns, out.points.size(), frame, size, lpcvt, &out.lpcvt);
    all.resize(ns + out.points.size());
    for (std::size_t i = 0; i < moved.size(); ++i) all[ns + i] = moved[i];
    out.lpcvt.moves_kept = keep_valid_moves(all, ns, frame, size, solid, locator, k, out);
  }
  return out;
}

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
  std::vector<double> sizes(surface.mesh.nodes.size());
  for (std::size_t v = 0; v < sizes.size(); ++v)
    sizes[v] = field.vertex_size(static_cast<std::int32_t>(v));
  Cloud cloud(surface.mesh.nodes, cell_side(sizes, 2 * std::sqrt(3.0) * k));
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
    VolumePoints out = frontal(surface, field, locator, options.k, options.inherit_frame,
                               smooth.get(), options.coherent_first ? &options.coherent : nullptr,
                               options.relax_iterations, options.lpcvt);
    jitter_points(out, field, options.jitter);
    return out;
  }
  std::size_t target = options.random_count;
  std::size_t frontal_count = 0;
  if (target == 0) {
    // Only the count is used: no relaxation.
    frontal_count = frontal(surface, field, locator, options.k, options.inherit_frame, smooth.get(),
                            options.coherent_first ? &options.coherent : nullptr, 0, {})
                        .points.size();
    target = frontal_count;
  }
  VolumePoints out = random_points(surface, field, locator, options.k, target, options.seed);
  out.frontal_count = frontal_count;
  jitter_points(out, field, options.jitter);
  return out;
}

}  // namespace hexfem
