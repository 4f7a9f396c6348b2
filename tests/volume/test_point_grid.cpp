// The volume points' cell grid against a brute-force scan: every point in a box is found, also
// points outside the grid's own box and points moved (removed and inserted again).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "mesher/point_grid.hpp"
#include "mesher/splitmix.hpp"

namespace hexfem {
namespace {

TEST(PointGrid, BoxQueriesFindWhatAScanFinds) {
  SplitMix rng{7};
  auto in = [&](double lo, double hi) { return lo + (hi - lo) * rng.uniform(); };
  // The grid spans [0, 10]^3; a tenth of the points lie outside it (its border cells hold them).
  std::vector<Vec3> x;
  for (int i = 0; i < 3000; ++i)
    x.push_back(i % 10 ? Vec3{in(0, 10), in(0, 10), in(0, 10)}
                       : Vec3{in(-3, 13), in(-3, 13), in(-3, 13)});
  PointGrid grid(CellLayout({0, 0, 0}, {10, 10, 10}, 0.7, 1 << 20));
  for (std::size_t i = 0; i < x.size(); ++i) grid.insert(static_cast<std::int32_t>(i), x[i]);
  // A third of them move.
  for (std::size_t i = 0; i < x.size(); i += 3) {
    grid.remove(static_cast<std::int32_t>(i), x[i]);
    x[i] = {in(-1, 11), in(-1, 11), in(-1, 11)};
    grid.insert(static_cast<std::int32_t>(i), x[i]);
  }
  std::size_t hits = 0;
  for (int q = 0; q < 400; ++q) {
    const Vec3 c{in(-2, 12), in(-2, 12), in(-2, 12)};
    const double r = in(0.1, 3);
    const Vec3 lo{c[0] - r, c[1] - r, c[2] - r}, hi{c[0] + r, c[1] + r, c[2] + r};
    auto inside = [&](const Vec3& p) {
      for (int a = 0; a < 3; ++a)
        if (p[a] < lo[a] || p[a] > hi[a]) return false;
      return true;
    };
    std::set<std::int32_t> want, got;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (inside(x[i])) want.insert(static_cast<std::int32_t>(i));
    std::size_t visits = 0;
    grid.for_each_near(lo, hi, [&](std::int32_t id) {
      ++visits;
      if (inside(x[id])) {
        EXPECT_TRUE(got.insert(id).second) << "listed twice: " << id;
      }
      return false;
    });
    EXPECT_EQ(got, want) << "query " << q;
    EXPECT_LE(visits, x.size());
    hits += want.size();
  }
  EXPECT_GT(hits, 2000u);
  // Stopping early: the first point the callback accepts ends the walk.
  int calls = 0;
  EXPECT_TRUE(grid.for_each_near({-5, -5, -5}, {15, 15, 15}, [&](std::int32_t) {
    ++calls;
    return true;
  }));
  EXPECT_EQ(calls, 1);
}

// A box far larger than the cap allows in cells of the asked side: larger cells, same answers.
TEST(PointGrid, ACapOnTheCellsMakesThemLarger) {
  PointGrid grid(CellLayout({0, 0, 0}, {1000, 1000, 1000}, 0.01, 1000));
  grid.insert(0, {999, 999, 999});
  grid.insert(1, {0.5, 0.5, 0.5});
  std::vector<std::int32_t> got;
  grid.for_each_near({998, 998, 998}, {1000, 1000, 1000}, [&](std::int32_t id) {
    got.push_back(id);
    return false;
  });
  EXPECT_NE(std::find(got.begin(), got.end(), 0), got.end());
}

}  // namespace
}  // namespace hexfem
