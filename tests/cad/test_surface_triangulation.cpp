// triangulate_face on a hand-made planar face (the unit square, z = 0, u = x, v = y): an
// interior point almost on a boundary segment would make a flat triangle (177° at the point,
// 1.1° at the segment's ends); it is taken out and the square becomes two right isosceles
// triangles. A well placed point is kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mesher/edge_points.hpp"
#include "mesher/surface_points.hpp"
#include "mesher/surface_triangulation.hpp"

namespace hexfem {
namespace {

double smallest_angle_deg(const FaceTriangles& t, const EdgePoints& e, const FaceBoundary& b,
                          const FacePoints& in) {
  const int nb = static_cast<int>(b.uv.size());
  auto xyz = [&](int id) -> const Vec3& {
    return id < nb ? e.xyz[static_cast<std::size_t>(b.node[static_cast<std::size_t>(id)])]
                   : in.xyz[static_cast<std::size_t>(id - nb)];
  };
  double m = 180;
  for (const auto& tri : t.triangles) {
    for (int i = 0; i < 3; ++i) {
      const Vec3 &p = xyz(tri[i]), &a = xyz(tri[(i + 1) % 3]), &c = xyz(tri[(i + 2) % 3]);
      const double ux = a[0] - p[0], uy = a[1] - p[1], vx = c[0] - p[0], vy = c[1] - p[1];
      m = std::min(
          m, std::abs(std::atan2(ux * vy - uy * vx, ux * vx + uy * vy)) * 180 / std::numbers::pi);
    }
  }
  return m;
}

struct Square {
  EdgePoints edges;
  FaceBoundary boundary;
  Square() {
    const Vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i < 4; ++i) {
      edges.xyz.push_back({corners[i][0], corners[i][1], 0});
      boundary.uv.push_back(corners[i]);
      boundary.node.push_back(i);
      boundary.segments.push_back({i, (i + 1) % 4});
    }
  }
};

FacePoints one_point(double u, double v) {
  FacePoints in;
  in.uv.push_back({u, v});
  in.xyz.push_back({u, v, 0});
  return in;
}

// Triangulates the square with one interior point at (u, v); expects whether the point is
// used, the number of triangles and their smallest angle (45°: the square's diagonal).
void expect_square(double u, double v, bool used, std::size_t triangles) {
  const Square sq;
  const FacePoints in = one_point(u, v);
  const FaceTriangles t = triangulate_face(1, sq.boundary, in, sq.edges, {1, 1});
  ASSERT_EQ(t.interior_used.size(), 1u);
  EXPECT_EQ(t.interior_used[0], used);
  EXPECT_EQ(t.triangles.size(), triangles);
  EXPECT_NEAR(smallest_angle_deg(t, sq.edges, sq.boundary, in), 45, 1e-9);
}

TEST(SurfaceTriangulation, PointAlmostOnASegmentIsTakenOut) {
  expect_square(0.5, 0.01, false, 2);
}

TEST(SurfaceTriangulation, WellPlacedPointIsKept) {
  expect_square(0.5, 0.5, true, 4);
}

}  // namespace
}  // namespace hexfem
