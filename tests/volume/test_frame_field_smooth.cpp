// The smooth 3D frame field (frame_field_smooth.hpp): the cube-symmetric quartic and its
// projection, the harmonic extension on a box (the box axes everywhere), on a cylinder (radial,
// tangential, axial) and on a box whose end faces are turned (a continuous turn where the
// nearest surface vertex's frame jumps), and the frontal points it gives on a box (the lattice).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mesher/frame_field_3d.hpp"
#include "mesher/frame_field_smooth.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/volume_points.hpp"
#include "tests/support/synthetic_surfaces.hpp"

namespace hexfem {
namespace {

using synthetic::cross3;
using synthetic::dot3;

constexpr double kDeg = std::numbers::pi / 180;

Frame rotation(Vec3 axis, double angle) {
  const double n = std::sqrt(dot3(axis, axis));
  for (double& x : axis) x /= n;
  const double c = std::cos(angle), s = std::sin(angle);
  Frame f;
  for (int i = 0; i < 3; ++i) {
    Vec3 e{0, 0, 0};
    e[i] = 1;
    const Vec3 kxe = cross3(axis, e);
    const double ke = dot3(axis, e);
    for (int a = 0; a < 3; ++a) f[i][a] = e[a] * c + kxe[a] * s + axis[a] * ke * (1 - c);
  }
  return f;
}

Frame compose(const Frame& r, const Frame& f) {  // r applied to each axis of f
  Frame out;
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a)
      out[i][a] = r[0][a] * f[i][0] + r[1][a] * f[i][1] + r[2][a] * f[i][2];
  return out;
}

void expect_orthonormal(const Frame& f) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(dot3(f[i], f[j]), i == j ? 1.0 : 0.0, 1e-9);
  EXPECT_NEAR(dot3(cross3(f[0], f[1]), f[2]), 1.0, 1e-9);  // right-handed
}

const Frame kAxes{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};

// A grid of one size per cell, the nodes within one size of the surface fixed: fine enough to
// compare the field with the cylinder's and the turned box's known shapes.
SmoothFrameOptions fine() {
  SmoothFrameOptions o;
  o.cell = 1;
  o.fixed_distance = 1;
  return o;
}

TEST(FrameFieldSmooth, QuarticIsCubeSymmetricAndProjectsBack) {
  const Frame r = rotation({1, 2, 3}, 0.7);
  const Frame same{r[1], Vec3{-r[0][0], -r[0][1], -r[0][2]}, r[2]};  // a quarter turn about d3
  const Quartic q = frame_quartic(r), qs = frame_quartic(same);
  for (int m = 0; m < 15; ++m) EXPECT_NEAR(q[m], qs[m], 1e-12);
  EXPECT_NEAR(frame_angle(r, same), 0.0, 1e-7);
  // p(x) = sum (d_i . x)^4: 1 on an axis, 1/3 on a cube diagonal.
  EXPECT_NEAR(quartic_value(q, r[1]), 1.0, 1e-12);
  Vec3 diag;
  for (int a = 0; a < 3; ++a) diag[a] = (r[0][a] + r[1][a] + r[2][a]) / std::sqrt(3.0);
  EXPECT_NEAR(quartic_value(q, diag), 1.0 / 3, 1e-12);
  // From 20 degrees off, the projection finds the frame again.
  const Frame start = compose(rotation({0, 1, 1}, 20 * kDeg), r);
  EXPECT_GT(frame_angle(start, r), 10 * kDeg);
  const Frame back = project_quartic(q, start, 50);
  expect_orthonormal(back);
  EXPECT_LT(frame_angle(back, r), 1e-6);
}

TEST(FrameFieldSmooth, BoxGivesTheAxesEverywhere) {
  const SurfaceMesh s = synthetic::box_surface({4, 3, 2}, {16, 12, 8});
  const FrameField3D field(s);
  const SolidLocator loc(s);
  const SmoothFrameField smooth(s, field, loc);
  ASSERT_GT(smooth.num_free(), 50u);
  for (std::size_t i = 0; i < smooth.num_nodes(); ++i)
    ASSERT_LT(frame_angle(smooth.node_frame(i), kAxes), 1e-6) << i;  // acos near 1
  for (double x : {0.1, 1.37, 2.0, 3.9})
    for (double z : {0.05, 0.8, 1.5}) {
      const Frame f = smooth.at({x, 1.1, z});
      expect_orthonormal(f);
      EXPECT_LT(frame_angle(f, kAxes), 1e-6);
    }
}

// Cylinder: the boundary frames are (tangential, axial, radial) on the side and (radial,
// tangential, axial) on the caps; the harmonic extension of r^4 e^{4 i theta} keeps that
// direction, so away from the axis (a singular line, whose discrete error reaches 10 degrees
// up to r = 0.45 R on this grid) the field is the cylindrical frame.
TEST(FrameFieldSmooth, CylinderGivesTheCylindricalFrame) {
  const double R = 1.0, H = 1.2, h = 0.1;
  const SurfaceMesh s = synthetic::cylinder_surface(R, H, h);
  const FrameField3D field(s);
  const SolidLocator loc(s);
  const SmoothFrameField smooth(s, field, loc, fine());
  ASSERT_GT(smooth.num_free(), 300u);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < smooth.num_nodes(); ++i) {
    if (!smooth.node_free(i)) continue;
    const Vec3 p = smooth.node_position(i);
    const double r = std::hypot(p[0], p[1]);
    expect_orthonormal(smooth.node_frame(i));
    if (r < 0.5 * R) continue;
    const Frame cyl{Vec3{p[0] / r, p[1] / r, 0}, Vec3{-p[1] / r, p[0] / r, 0}, Vec3{0, 0, 1}};
    EXPECT_LT(frame_angle(smooth.node_frame(i), cyl), 6 * kDeg) << p[0] << " " << p[1];
    ++checked;
  }
  EXPECT_GT(checked, 100u);
  // At the side's vertices, the frame is the boundary frame up to the discretization.
  for (std::size_t v = 0; v < s.mesh.nodes.size(); ++v) {
    const Vec3& p = s.mesh.nodes[v];
    if (p[2] < 0.3 || p[2] > H - 0.3) continue;
    EXPECT_LT(frame_angle(smooth.at(p), field.vertex_frame(static_cast<std::int32_t>(v))),
              8 * kDeg);
  }
}

// A long box whose two end faces' frames are turned by 30 degrees about x: the nearest
// surface vertex's frame jumps by 30 degrees where the end faces' region meets the side
// faces'; the smooth field turns over several cells, and is the axes far from the ends.
TEST(FrameFieldSmooth, TurnedEndFacesGiveAContinuousTurn) {
  SurfaceMesh s = synthetic::box_surface({4, 1, 1}, {40, 10, 10});
  const Frame turn = rotation({1, 0, 0}, 30 * kDeg);
  for (std::size_t v = 0; v < s.mesh.nodes.size(); ++v) {
    const double x = s.mesh.nodes[v][0];
    if ((x == 0 || x == 4) && std::abs(s.frame[v][2][0]) == 1) s.frame[v] = compose(turn, kAxes);
  }
  const FrameField3D field(s);
  const SolidLocator loc(s);
  const SmoothFrameField smooth(s, field, loc, fine());
  const auto d = smooth.dims();
  const std::size_t step[3] = {1, static_cast<std::size_t>(d[0]),
                               static_cast<std::size_t>(d[0]) * d[1]};
  double worst_smooth = 0, worst_nearest = 0;
  for (std::size_t i = 0; i < smooth.num_nodes(); ++i) {
    if (!smooth.node_free(i)) continue;
    expect_orthonormal(smooth.node_frame(i));
    const Vec3 p = smooth.node_position(i);
    const Frame& near_i = field.vertex_frame(field.nearest_vertex(p));
    for (std::size_t st : step) {
      const std::size_t j = i + st;
      if (j >= smooth.num_nodes() || !smooth.node_free(j)) continue;
      worst_smooth =
          std::max(worst_smooth, frame_angle(smooth.node_frame(i), smooth.node_frame(j)));
      const Frame& near_j = field.vertex_frame(field.nearest_vertex(smooth.node_position(j)));
      worst_nearest = std::max(worst_nearest, frame_angle(near_i, near_j));
    }
  }
  EXPECT_GT(worst_nearest, 29 * kDeg);
  EXPECT_LT(worst_smooth, 12 * kDeg);
  EXPECT_LT(frame_angle(smooth.at({2.0, 0.5, 0.5}), kAxes), 0.5 * kDeg);
  EXPECT_LT(frame_angle(smooth.at({2.0, 0.3, 0.6}), kAxes), 0.5 * kDeg);
  // Along the axis from an end face: a turn about x only, decreasing from most of 30 degrees
  // (the side faces pull the rest) to none.
  double previous = 90 * kDeg;
  for (double x = 0.1; x < 1.5; x += 0.1) {
    const Frame f = smooth.at({x, 0.5, 0.5});
    double along_x = 0;
    for (const Vec3& e : f) along_x = std::max(along_x, std::abs(e[0]));
    EXPECT_NEAR(along_x, 1.0, 1e-9);
    const double angle = frame_angle(f, kAxes);
    EXPECT_LE(angle, previous + 1e-9) << x;
    if (x < 0.15) {
      EXPECT_GT(angle, 15 * kDeg);
    }
    previous = angle;
  }
  EXPECT_LT(previous, 1 * kDeg);
}

// On a box the smooth field is the axes: the frontal points are the same lattice as with the
// default (inherited) frames.
TEST(FrameFieldSmooth, FrontalPointsOnABoxStayOnTheLattice) {
  const SurfaceMesh s = synthetic::box_surface({2, 1.5, 1}, {8, 6, 4});
  const FrameField3D field(s);
  const SolidLocator loc(s);
  VolumePointsOptions o;
  const VolumePoints base = insert_volume_points(s, field, loc, o);
  o.smooth_frame = true;
  const VolumePoints vp = insert_volume_points(s, field, loc, o);
  EXPECT_EQ(vp.points.size(), base.points.size());
  EXPECT_EQ(vp.points.size(), 7u * 5u * 3u);
  for (const Vec3& p : vp.points)
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(p[a] / 0.25, std::round(p[a] / 0.25), 1e-9) << p[0] << " " << p[1];
}

}  // namespace
}  // namespace hexfem
