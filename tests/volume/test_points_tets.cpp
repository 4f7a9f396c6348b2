// Stages 1-3 of the volume mesher on surfaces with known answers: frame field, frontal points,
// TetGen.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

#include "mesher/frame_field_3d.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/tetrahedralize.hpp"
#include "mesher/volume_points.hpp"
#include "tests/support/synthetic_surfaces.hpp"

namespace hexfem {
namespace {

double tet_volume(const TetMesh& m, std::size_t t) {
  const auto& T = m.tets[t];
  const Vec3 &a = m.nodes[T[0]], &b = m.nodes[T[1]], &c = m.nodes[T[2]], &d = m.nodes[T[3]];
  const Vec3 u = synthetic::sub3(b, a), v = synthetic::sub3(c, a), w = synthetic::sub3(d, a);
  return synthetic::dot3(u, synthetic::cross3(v, w)) / 6.0;
}

TEST(SyntheticSurfaces, BoxAndCylinderAreClosed) {
  // SolidLocator checks closedness and throws otherwise.
  EXPECT_NO_THROW(SolidLocator(synthetic::box_surface({2, 1, 1}, {8, 4, 4})));
  EXPECT_NO_THROW(SolidLocator(synthetic::cylinder_surface(1.0, 2.0, 0.2)));
}

TEST(SolidLocator, InsideAndDistanceOnABox) {
  const SurfaceMesh s = synthetic::box_surface({2, 1, 1}, {8, 4, 4});
  const SolidLocator loc(s);
  EXPECT_TRUE(loc.inside(1, {1.0, 0.5, 0.5}));
  EXPECT_TRUE(loc.inside(1, {0.25, 0.25, 0.25}));  // on grid diagonals' planes: re-shot rays
  EXPECT_FALSE(loc.inside(1, {2.5, 0.5, 0.5}));
  EXPECT_FALSE(loc.inside(1, {1.0, -0.1, 0.5}));
  EXPECT_EQ(loc.locate({1.0, 0.5, 0.5}), 1);
  EXPECT_EQ(loc.locate({3.0, 0.5, 0.5}), 0);
  EXPECT_TRUE(loc.near_boundary(1, {1.0, 0.5, 0.1}, 0.11));
  EXPECT_FALSE(loc.near_boundary(1, {1.0, 0.5, 0.1}, 0.09));
  EXPECT_TRUE(loc.segment_hits_boundary(1, {1.0, 0.5, 0.5}, {1.0, 0.5, 1.5}));
  EXPECT_FALSE(loc.segment_hits_boundary(1, {1.0, 0.5, 0.5}, {1.0, 0.5, 0.9}));
}

// Distances and ray casts against the faces of the 2 x 1 x 1 box, checked by hand.
TEST(SolidLocator, DistanceAndRayOnABox) {
  const SurfaceMesh s = synthetic::box_surface({2, 1, 1}, {8, 4, 4});
  const SolidLocator loc(s);
  std::int32_t tri = -1;
  EXPECT_NEAR(loc.distance(1, {1.0, 0.5, 0.3}, &tri), 0.3, 1e-12);
  ASSERT_GE(tri, 0);
  EXPECT_EQ(s.mesh.bface_cad_face[tri], 5);  // z = 0
  EXPECT_NEAR(loc.distance(1, {1.9, 0.45, 0.5}), 0.1, 1e-12);
  EXPECT_NEAR(loc.distance(1, {3.0, 0.5, 0.5}), 1.0, 1e-12);  // outside: to the face x = 2
  // From inside along +x: the face x = 2.
  EXPECT_NEAR(loc.ray_distance(1, {0.3, 0.4, 0.6}, {1, 0, 0}, -1, &tri), 1.7, 1e-12);
  EXPECT_EQ(s.mesh.bface_cad_face[tri], 2);
  // From a surface node of the face z = 0 inward: its own triangles are skipped, so the ray
  // meets the face z = 1 across the box.
  std::int32_t v = -1;
  for (std::size_t i = 0; i < s.mesh.nodes.size(); ++i)
    if (std::abs(s.mesh.nodes[i][0] - 1.0) < 1e-12 && std::abs(s.mesh.nodes[i][1] - 0.5) < 1e-12 &&
        std::abs(s.mesh.nodes[i][2]) < 1e-12)
      v = static_cast<std::int32_t>(i);
  ASSERT_GE(v, 0);
  EXPECT_NEAR(loc.ray_distance(1, s.mesh.nodes[v], {0, 0, 1}, v, &tri), 1.0, 1e-12);
  EXPECT_EQ(s.mesh.bface_cad_face[tri], 6);
  // Leaving the box: nothing behind.
  EXPECT_TRUE(std::isinf(loc.ray_distance(1, {5, 5, 5}, {1, 0, 0}, -1, &tri)));
  EXPECT_EQ(tri, -1);
}

TEST(SolidLocator, OpenSurfaceIsAnError) {
  SurfaceMesh s = synthetic::box_surface({1, 1, 1}, {2, 2, 2});
  s.mesh.bface_nodes.resize(s.mesh.bface_nodes.size() - 4);
  s.mesh.bface_cad_face.pop_back();
  s.mesh.bface_physical.pop_back();
  EXPECT_THROW(SolidLocator{s}, Error);
}

TEST(FrameField3D, NearestVertexFrameAndSize) {
  const SurfaceMesh s = synthetic::cylinder_surface(1.0, 2.0, 0.25);
  const FrameField3D f(s);
  // Near the lateral surface at angle 0, mid-height: the frame's normal is radial (+x).
  const std::int32_t v = f.nearest_vertex({0.9, 0.0, 1.0});
  EXPECT_NEAR(s.mesh.nodes[v][0], 1.0, 1e-12);
  EXPECT_NEAR(f.vertex_frame(v)[2][0], 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(f.vertex_size(v), 0.25);
  SurfaceMesh bad = s;
  bad.size[3] = 0;
  EXPECT_THROW(FrameField3D{bad}, Error);
}

TEST(FrameField3D, SizeGrowsAwayFromASmallVertexUpToTheLargestSize) {
  SurfaceMesh s = synthetic::cylinder_surface(1.0, 2.0, 0.25);
  const std::int32_t v = 5;
  s.size[v] = 0.01;  // as at a tiny CAD feature
  const FrameField3D f(s);
  const Vec3 x = s.mesh.nodes[v];
  EXPECT_DOUBLE_EQ(f.size_at(x, v), 0.01);
  // 0.1 away: 0.01 + 0.3 * 0.1 by hand; far away: capped by the largest surface size 0.25.
  const Vec3 near{x[0], x[1], x[2] + 0.1}, far{x[0], x[1], x[2] + 5};
  EXPECT_NEAR(f.size_at(near, v), 0.04, 1e-12);
  EXPECT_DOUBLE_EQ(f.size_at(far, v), 0.25);
}

// at_max_size is the nearest-vertex size test without the nearest vertex: it says yes exactly
// where no vertex lowers the size (all tried by brute force), so there the size at the true
// nearest vertex is the largest; and it says yes everywhere on a uniform size field. Points on a
// grid through and around the cylinder.
TEST(FrameField3D, AtMaxSizeAgreesWithTheSizeAtTheNearestVertex) {
  SurfaceMesh s = synthetic::cylinder_surface(1.0, 2.0, 0.25);
  const FrameField3D uniform(s);
  s.size[5] = 0.01;
  s.size[40] = 0.2;
  const FrameField3D f(s);
  int yes = 0, no = 0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j)
      for (int k = 0; k <= 24; ++k) {
        const Vec3 p{-1.2 + 0.12 * i, -1.2 + 0.12 * j, -0.2 + 0.1 * k};
        EXPECT_TRUE(uniform.at_max_size(p));
        std::int32_t best = 0;
        double d_best = 1e300;
        for (std::size_t v = 0; v < s.mesh.nodes.size(); ++v) {
          const Vec3 d = synthetic::sub3(p, s.mesh.nodes[v]);
          if (synthetic::dot3(d, d) < d_best) {
            d_best = synthetic::dot3(d, d);
            best = static_cast<std::int32_t>(v);
          }
        }
        const bool at_max = f.size_at(p, best) == f.max_size();
        // Exactly: no vertex at all lowers the size at p (the index may only skip vertices
        // that cannot).
        bool lowered = false;
        for (std::size_t v = 0; v < s.mesh.nodes.size(); ++v)
          lowered = lowered || f.size_at(p, static_cast<std::int32_t>(v)) < f.max_size();
        EXPECT_EQ(f.at_max_size(p), !lowered) << p[0] << " " << p[1] << " " << p[2];
        if (f.at_max_size(p)) {
          EXPECT_TRUE(at_max) << p[0] << " " << p[1] << " " << p[2];
          ++yes;
        } else {
          ++no;
        }
      }
  // Both answers occur: the small vertices lower the size near them only.
  EXPECT_GT(yes, 1000);
  EXPECT_GT(no, 10);
}

// One surface vertex made 10x finer (as at a tiny CAD feature): the fine points it grows stay near
// it, graded back to h, instead of filling the whole region of the volume nearest to it at its
// size (MVE at h = 9.55 had 1.77M interior points that way, 90 % at one vertex's size).
TEST(VolumePoints, ATinySurfaceSizeStaysLocal) {
  SurfaceMesh s = synthetic::box_surface({2.5, 2.5, 2.5}, {10, 10, 10});
  const FrameField3D uniform_field(s);
  const SolidLocator loc(s);
  const std::size_t uniform = insert_volume_points(s, uniform_field, loc).points.size();
  ASSERT_EQ(uniform, 9u * 9u * 9u);
  // The surface vertex at the centre of the face x = 0.
  std::int32_t v = uniform_field.nearest_vertex({0, 1.25, 1.25});
  ASSERT_NEAR(s.mesh.nodes[v][1], 1.25, 1e-12);
  s.size[v] = 0.025;
  const FrameField3D field(s);
  const VolumePoints vp = insert_volume_points(s, field, loc);
  // Points off the lattice of step 0.25 come from the fine vertex: they lie within the grading
  // distance (0.25 - 0.025) / 0.3 = 0.75 of it, plus a step. Its nearest region (a column 0.25
  // wide to the middle of the box) filled at 0.025 would hold ~4,000 more points.
  std::size_t off_lattice = 0;
  for (const Vec3& p : vp.points) {
    bool on = true;
    for (int a = 0; a < 3; ++a) on = on && std::abs(p[a] / 0.25 - std::round(p[a] / 0.25)) < 1e-6;
    if (on) continue;
    ++off_lattice;
    EXPECT_LT(std::hypot(p[0], p[1] - 1.25, p[2] - 1.25), 1.0);
  }
  EXPECT_GT(off_lattice, 0u);
  std::printf("uniform %zu, with the fine vertex %zu (%zu off the lattice)\n", uniform,
              vp.points.size(), off_lattice);
  EXPECT_LT(vp.points.size(), uniform + 300);
}

// On a box whose surface nodes are a lattice of step h with frames = axes, the frontal insertion
// must fill exactly the interior lattice points.
TEST(VolumePoints, FrontalFillsTheBoxLattice) {
  const int n[3] = {6, 5, 4};
  const SurfaceMesh s = synthetic::box_surface({1.5, 1.25, 1.0}, {6, 5, 4});
  const FrameField3D field(s);
  const SolidLocator loc(s);
  const VolumePoints vp = insert_volume_points(s, field, loc);
  ASSERT_EQ(vp.points.size(), static_cast<std::size_t>((n[0] - 1) * (n[1] - 1) * (n[2] - 1)));
  std::set<std::array<long, 3>> seen;
  for (const Vec3& p : vp.points) {
    std::array<long, 3> ijk;
    for (int a = 0; a < 3; ++a) {
      const double x = p[a] / 0.25;
      ijk[a] = std::lround(x);
      EXPECT_NEAR(x, ijk[a], 1e-9);
      EXPECT_GT(ijk[a], 0);
      EXPECT_LT(ijk[a], n[a]);
    }
    seen.insert(ijk);
  }
  EXPECT_EQ(seen.size(), vp.points.size());
  for (int sid : vp.solid) EXPECT_EQ(sid, 1);
  // Jitter moves each point by at most jitter * h per coordinate.
  VolumePointsOptions jo;
  jo.jitter = 1e-6;
  const VolumePoints jittered = insert_volume_points(s, field, loc, jo);
  ASSERT_EQ(jittered.points.size(), vp.points.size());
  double most = 0;
  for (std::size_t i = 0; i < vp.points.size(); ++i)
    for (int a = 0; a < 3; ++a)
      most = std::max(most, std::abs(jittered.points[i][a] - vp.points[i][a]));
  EXPECT_GT(most, 0.0);
  EXPECT_LE(most, 1e-6 * 0.25);
}

// A point's frame is the frame of the surface vertex its front started from: every step (of
// length h, the size being uniform) is taken along that one frame, so each interior point is its
// start vertex plus whole numbers of steps along the start vertex's frame. On a cylinder whose
// disks' frames lean 25 degrees off the axis, the paper's nearest-vertex frames
// (inherit_frame = false) switch to the lateral face's frames as the disks' fronts go deeper,
// and some points are on no such front.
TEST(VolumePoints, FrontsKeepTheFrameTheyStartedWith) {
  const double h = 0.125;
  SurfaceMesh s = synthetic::cylinder_surface(1.0, 1.0, h);
  const double c = std::cos(25 * std::numbers::pi / 180),
               sn = std::sin(25 * std::numbers::pi / 180);
  for (auto& f : s.frame) {
    if (std::abs(f[2][2]) < 0.5) continue;  // lateral
    const double z = f[2][2] > 0 ? 1 : -1;
    f = {Vec3{1, 0, 0}, Vec3{0, z * c, -z * sn}, Vec3{0, z * sn, z * c}};
  }
  const FrameField3D field(s);
  const SolidLocator loc(s);
  auto on_a_front = [&](const Vec3& p) {
    for (std::size_t v = 0; v < s.mesh.nodes.size(); ++v) {
      const Vec3 d = synthetic::sub3(p, s.mesh.nodes[v]);
      bool whole = true;
      for (int i = 0; i < 3 && whole; ++i) {
        const double steps =
            synthetic::dot3(d, field.vertex_frame(static_cast<std::int32_t>(v))[i]) / h;
        whole = std::abs(steps - std::round(steps)) < 1e-9;
      }
      if (whole) return true;
    }
    return false;
  };
  for (bool inherit : {true, false}) {
    VolumePointsOptions o;
    o.inherit_frame = inherit;
    const VolumePoints vp = insert_volume_points(s, field, loc, o);
    ASSERT_GT(vp.points.size(), 500u);
    std::size_t off = 0;
    for (const Vec3& p : vp.points) off += !on_a_front(p);
    if (inherit)
      EXPECT_EQ(off, 0u);
    else
      EXPECT_GT(off, 0u);
    std::printf("inherit %d: %zu points, %zu on no front\n", inherit, vp.points.size(), off);
  }
}

TEST(VolumePoints, RandomModeMatchesTheFrontalCountAndStaysInside) {
  const SurfaceMesh s = synthetic::cylinder_surface(1.0, 1.0, 0.2);
  const FrameField3D field(s);
  const SolidLocator loc(s);
  VolumePointsOptions o;
  o.random = true;
  const VolumePoints vp = insert_volume_points(s, field, loc, o);
  EXPECT_GT(vp.frontal_count, 0u);
  EXPECT_LE(vp.points.size(), vp.frontal_count);
  EXPECT_GT(vp.points.size(), vp.frontal_count / 2);
  for (const Vec3& p : vp.points) {
    EXPECT_LT(std::hypot(p[0], p[1]), 1.0 - 0.7 * 0.2 + 1e-9);
    EXPECT_GT(p[2], 0.7 * 0.2 - 1e-9);
    EXPECT_LT(p[2], 1.0 - 0.7 * 0.2 + 1e-9);
  }
  o.k = 1.5;
  EXPECT_THROW(insert_volume_points(s, field, loc, o), Error);
}

// Without TetGen's Delaunay recovery (the default), the boundary recovery's flips may leave a few
// flat tets (four coplanar lattice points, or a quad of a planar face with its other diagonal
// inside). None is inverted; the recombination absorbs or flips them like any sliver. With the
// recovery every tet is positive, as "tetgen -pY" gives.
// A 6 x 6 x 6 box with a 2 x 2 x 2 cavity in its middle: TetGen fills the cavity too (no hole
// point is given), and the regions split by the surface triangles must drop those tets. The
// tets left hold the 208 of the solid, and every one has its centroid in the wall.
TEST(Tetrahedralize, DropsTheTetsOfAnInnerCavity) {
  SurfaceMesh s = synthetic::box_surface({6, 6, 6}, {6, 6, 6});
  const SurfaceMesh inner = synthetic::box_surface({2, 2, 2}, {2, 2, 2});
  const auto offset = static_cast<std::int32_t>(s.mesh.nodes.size());
  for (std::size_t v = 0; v < inner.mesh.nodes.size(); ++v) {
    const Vec3& p = inner.mesh.nodes[v];
    s.mesh.nodes.push_back({p[0] + 2, p[1] + 2, p[2] + 2});
    const auto& f = inner.frame[v];
    s.frame.push_back({f[0], f[1], {-f[2][0], -f[2][1], -f[2][2]}});
    s.size.push_back(inner.size[v]);
    s.on_edge.push_back(inner.on_edge[v]);
  }
  for (std::size_t t = 0; t < inner.mesh.num_bfaces(); ++t) {  // reversed: normals into the cavity
    const auto* f = inner.mesh.bface(t);
    s.mesh.add_bface(f[0] + offset, f[2] + offset, f[1] + offset, -1,
                     inner.mesh.bface_cad_face[t] + 6);
  }
  s.faces_of_solid = {{}, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}};
  const SolidLocator loc(s);
  // Points in the wall only, on the lattice of the surfaces (step 1), and none in the cavity.
  std::vector<Vec3> points;
  auto in_cavity = [](const Vec3& p) {
    return p[0] >= 2 && p[0] <= 4 && p[1] >= 2 && p[1] <= 4 && p[2] >= 2 && p[2] <= 4;
  };
  for (int i = 1; i < 6; ++i)
    for (int j = 1; j < 6; ++j)
      for (int k = 1; k < 6; ++k)
        if (const Vec3 p{i + 0.0, j + 0.0, k + 0.0}; !in_cavity(p)) points.push_back(p);
  const TetMesh tm = tetrahedralize(s, points, loc);
  EXPECT_GT(tm.dropped_tets, 0u);
  double vol = 0;
  for (std::size_t t = 0; t < tm.tets.size(); ++t) {
    vol += tet_volume(tm, t);
    Vec3 c{0, 0, 0};
    for (std::int32_t v : tm.tets[t])
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * tm.nodes[v][a];
    EXPECT_FALSE(in_cavity(c)) << "tet " << t;
    EXPECT_EQ(tm.tet_solid[t], 1);
  }
  EXPECT_NEAR(vol, 208.0, 1e-9);
}

TEST(Tetrahedralize, KeepsTheSurfaceAndFillsTheVolume) {
  const SurfaceMesh s = synthetic::cylinder_surface(1.0, 1.5, 0.25);
  const FrameField3D field(s);
  const SolidLocator loc(s);
  const VolumePoints vp = insert_volume_points(s, field, loc);
  const TetMesh tm = tetrahedralize(s, vp.points, loc);
  EXPECT_EQ(tm.nodes.size(), s.mesh.nodes.size() + vp.points.size() + tm.steiner_points);
  double vol = 0;
  std::size_t flat = 0;
  for (std::size_t t = 0; t < tm.tets.size(); ++t) {
    const double v = tet_volume(tm, t);
    EXPECT_GE(v, 0);
    flat += v <= 1e-12;
    vol += v;
  }
  EXPECT_LT(flat, tm.tets.size() / 100);
  const TetMesh recovered = tetrahedralize(s, vp.points, loc, true);
  for (std::size_t t = 0; t < recovered.tets.size(); ++t) EXPECT_GT(tet_volume(recovered, t), 0);
  // Volume of the polyhedron bounded by the surface triangles (divergence theorem).
  double poly = 0;
  for (std::size_t t = 0; t < s.mesh.num_bfaces(); ++t) {
    const auto* f = s.mesh.bface(t);
    poly += synthetic::dot3(s.mesh.nodes[f[0]],
                            synthetic::cross3(s.mesh.nodes[f[1]], s.mesh.nodes[f[2]])) /
            6.0;
  }
  EXPECT_NEAR(vol, poly, 1e-9 * poly);
  // Every surface triangle is a face of exactly one tet.
  std::set<std::array<std::int32_t, 3>> faces;
  for (const auto& T : tm.tets)
    for (int i = 0; i < 4; ++i) {
      std::array<std::int32_t, 3> f{T[(i + 1) % 4], T[(i + 2) % 4], T[(i + 3) % 4]};
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
  for (std::size_t t = 0; t < s.mesh.num_bfaces(); ++t) {
    std::array<std::int32_t, 3> f{s.mesh.bface(t)[0], s.mesh.bface(t)[1], s.mesh.bface(t)[2]};
    std::sort(f.begin(), f.end());
    EXPECT_TRUE(faces.count(f));
  }
}

TEST(Tetrahedralize, SelfIntersectingSurfaceNamesTheFaces) {
  // Two overlapping boxes in one "solid": their surfaces cross.
  SurfaceMesh a = synthetic::box_surface({1, 1, 1}, {2, 2, 2});
  const SurfaceMesh b = synthetic::box_surface({1, 1, 1}, {2, 2, 2});
  const auto offset = static_cast<std::int32_t>(a.mesh.nodes.size());
  for (std::size_t v = 0; v < b.mesh.nodes.size(); ++v) {
    Vec3 p = b.mesh.nodes[v];
    p[0] += 0.5;
    p[1] += 0.3;
    p[2] += 0.2;
    a.mesh.nodes.push_back(p);
    a.frame.push_back(b.frame[v]);
    a.size.push_back(b.size[v]);
    a.on_edge.push_back(b.on_edge[v]);
  }
  for (std::size_t t = 0; t < b.mesh.num_bfaces(); ++t)
    a.mesh.add_bface(b.mesh.bface(t)[0] + offset, b.mesh.bface(t)[1] + offset,
                     b.mesh.bface(t)[2] + offset, -1, b.mesh.bface_cad_face[t] + 6);
  a.faces_of_solid = {{}, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}};
  const SolidLocator loc(a);
  try {
    tetrahedralize(a, {}, loc);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("intersects itself"), std::string::npos) << msg;
    EXPECT_NE(msg.find("CAD face"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace hexfem
