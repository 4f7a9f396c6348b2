// Point ids in a uniform grid of cells, for the box queries of the volume points. The frontal
// insertion adds a million points one at a time and asks about ten million boxes; a cell list
// makes an insertion a push and a query a walk over the few cells the box overlaps (the R-tree
// before spent about 5 of the stage's 8.8 s at a million points in its inserts and queries).
// Points outside the grid's box go to its border cells: every query still finds them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// A box cut into cells, numbered x fastest: the grids' shared layout.
struct CellLayout {
  Vec3 lo{0, 0, 0};
  double inv_side = 1;
  std::int64_t n[3] = {1, 1, 1};

  CellLayout() = default;
  // Cells of side `cell` (at least) over [lo, hi], at most max_cells of them (larger cells then).
  CellLayout(const Vec3& box_lo, const Vec3& hi, double cell, std::size_t max_cells) : lo(box_lo) {
    double side = cell > 0 && std::isfinite(cell) ? cell : 1;
    for (;; side *= 1.25) {
      std::size_t total = 1;
      for (int a = 0; a < 3; ++a) {
        const double span = std::max(hi[a] - lo[a], 0.0);
        n[a] = static_cast<std::int64_t>(std::min(span / side, 1e6)) + 1;
        total *= static_cast<std::size_t>(n[a]);
      }
      if (total <= std::max<std::size_t>(max_cells, 1)) break;
    }
    inv_side = 1 / side;
  }
  // The same over the points' bounding box.
  static CellLayout around(const std::vector<Vec3>& points, double cell, std::size_t max_cells) {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    if (!points.empty()) lo = hi = points[0];
    for (const Vec3& p : points)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    return CellLayout(lo, hi, cell, max_cells);
  }
  std::size_t size() const { return static_cast<std::size_t>(n[0] * n[1] * n[2]); }
  // The cell index along axis a of coordinate x, clamped to the grid. Monotone in x: a point
  // inside a box lies in a cell between those of the box's corners.
  std::int64_t clamped(double x, int a) const {
    const double u = (x - lo[a]) * inv_side;
    if (!(u > 0)) return 0;  // also NaN
    return std::min(static_cast<std::int64_t>(std::min(u, 1e15)), n[a] - 1);
  }
  std::size_t clamped_cell(const Vec3& p) const {
    return static_cast<std::size_t>((clamped(p[2], 2) * n[1] + clamped(p[1], 1)) * n[0] +
                                    clamped(p[0], 0));
  }
  // The cell of p, or -1 when p lies outside the grid.
  std::int64_t cell_inside(const Vec3& p) const {
    std::int64_t c = 0;
    for (int a = 2; a >= 0; --a) {
      const double u = (p[a] - lo[a]) * inv_side;
      if (!(u >= 0 && u < static_cast<double>(n[a]))) return -1;
      c = c * n[a] + static_cast<std::int64_t>(u);
    }
    return c;
  }
};

class PointGrid {
 public:
  explicit PointGrid(const CellLayout& layout) : cells_(layout), head_(layout.size(), -1) {}

  void insert(std::int32_t id, const Vec3& p) {
    if (static_cast<std::size_t>(id) >= next_.size()) next_.resize(id + 1, -1);
    std::int32_t& h = head_[cells_.clamped_cell(p)];
    next_[id] = h;
    h = id;
  }
  // Takes id out of the cell of p (its position when inserted).
  void remove(std::int32_t id, const Vec3& p) {
    std::int32_t* at = &head_[cells_.clamped_cell(p)];
    while (*at >= 0 && *at != id) at = &next_[*at];
    if (*at == id) *at = next_[id];
  }
  // Calls f(id) for every id in a cell that [lo, hi] overlaps (a superset of the points in the
  // box, which the caller tests) until f returns true; returns whether one did.
  template <class F>
  bool for_each_near(const Vec3& lo, const Vec3& hi, F&& f) const {
    std::int64_t a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = cells_.clamped(lo[k], k);
      b[k] = cells_.clamped(hi[k], k);
    }
    for (std::int64_t z = a[2]; z <= b[2]; ++z)
      for (std::int64_t y = a[1]; y <= b[1]; ++y) {
        const std::int64_t row = (z * cells_.n[1] + y) * cells_.n[0];
        for (std::int64_t x = a[0]; x <= b[0]; ++x)
          for (std::int32_t id = head_[row + x]; id >= 0; id = next_[id])
            if (f(id)) return true;
      }
    return false;
  }

 private:
  CellLayout cells_;
  std::vector<std::int32_t> head_, next_;
};

}  // namespace hexfem
