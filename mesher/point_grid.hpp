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

class PointGrid {
 public:
  // Cells of side `cell` (at least) over [lo, hi], at most max_cells of them (larger cells then).
  PointGrid(const Vec3& lo, const Vec3& hi, double cell, std::size_t max_cells) : lo_(lo) {
    double side = cell > 0 && std::isfinite(cell) ? cell : 1;
    for (;;) {
      std::size_t total = 1;
      for (int a = 0; a < 3; ++a) {
        const double span = std::max(hi[a] - lo[a], 0.0);
        n_[a] = static_cast<std::int64_t>(std::min(span / side, 1e6)) + 1;
        total *= static_cast<std::size_t>(n_[a]);
      }
      if (total <= std::max<std::size_t>(max_cells, 1)) {
        head_.assign(total, -1);
        break;
      }
      side *= 1.25;
    }
    inv_ = 1 / side;
  }

  void insert(std::int32_t id, const Vec3& p) {
    if (static_cast<std::size_t>(id) >= next_.size()) next_.resize(id + 1, -1);
    std::int32_t& h = head_[cell_of(p)];
    next_[id] = h;
    h = id;
  }
  // Takes id out of the cell of p (its position when inserted).
  void remove(std::int32_t id, const Vec3& p) {
    std::int32_t* at = &head_[cell_of(p)];
    while (*at >= 0 && *at != id) at = &next_[*at];
    if (*at == id) *at = next_[id];
  }
  // Calls f(id) for every id in a cell that [lo, hi] overlaps (a superset of the points in the
  // box, which the caller tests) until f returns true; returns whether one did.
  template <class F>
  bool for_each_near(const Vec3& lo, const Vec3& hi, F&& f) const {
    std::int64_t a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = index(lo[k], k);
      b[k] = index(hi[k], k);
    }
    for (std::int64_t z = a[2]; z <= b[2]; ++z)
      for (std::int64_t y = a[1]; y <= b[1]; ++y) {
        const std::int64_t row = (z * n_[1] + y) * n_[0];
        for (std::int64_t x = a[0]; x <= b[0]; ++x)
          for (std::int32_t id = head_[row + x]; id >= 0; id = next_[id])
            if (f(id)) return true;
      }
    return false;
  }

 private:
  // Monotone in x: a point inside a box lies in a cell between those of the box's corners.
  std::int64_t index(double x, int a) const {
    const double u = (x - lo_[a]) * inv_;
    if (!(u > 0)) return 0;  // also NaN
    return std::min(static_cast<std::int64_t>(std::min(u, 1e15)), n_[a] - 1);
  }
  std::size_t cell_of(const Vec3& p) const {
    return static_cast<std::size_t>((index(p[2], 2) * n_[1] + index(p[1], 1)) * n_[0] +
                                    index(p[0], 0));
  }
  Vec3 lo_;
  double inv_ = 1;
  std::int64_t n_[3] = {1, 1, 1};
  std::vector<std::int32_t> head_, next_;
};

}  // namespace hexfem
