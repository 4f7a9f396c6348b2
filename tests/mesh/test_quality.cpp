// Volumes and scaled Jacobians against hand computations.
#include <gtest/gtest.h>

#include <cmath>

#include "mesh_fixtures.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {
namespace {

using testing::unit_hex;

TEST(Quality, UnitCubeHex) {
  const MixedMesh m = unit_hex();
  EXPECT_NEAR(cell_volume(m, 0), 1.0, 1e-14);
  EXPECT_NEAR(cell_min_scaled_jacobian(m, 0), 1.0, 1e-14);
  EXPECT_FALSE(cell_is_inverted(m, 0));
  const MeshStats s = compute_stats(m);
  EXPECT_NEAR(s.q_mean, 1.0, 1e-14);
  EXPECT_NEAR(s.h_vol, 100.0, 1e-12);
  EXPECT_TRUE(s.watertight);
}

TEST(Quality, ShearedHex) {
  // x += 0.5 y keeps the volume; every corner sees edges (1,0,0), (0.5,1,0), (0,0,1):
  // det 1 over lengths sqrt(1.25) -> 1/sqrt(1.25).
  const MixedMesh m = unit_hex(0.5);
  EXPECT_NEAR(cell_volume(m, 0), 1.0, 1e-14);
  EXPECT_NEAR(cell_min_scaled_jacobian(m, 0), 1.0 / std::sqrt(1.25), 1e-14);
}

TEST(Quality, NonPlanarHexVolumeIsTheTrilinearOne) {
  // Lift one top corner by 0.3: the trilinear map's volume is 1 + 0.3/4 (the top face is the
  // bilinear patch z = 1 + 0.3 x y, whose mean height over the unit square is 0.3/4).
  MixedMesh m = unit_hex();
  m.nodes[6][2] += 0.3;
  EXPECT_NEAR(cell_volume(m, 0), 1.0 + 0.3 / 4, 1e-14);
}

TEST(Quality, RegularTet) {
  MixedMesh m;
  const double a = 2.0;
  m.nodes = {{0, 0, 0},
             {a, 0, 0},
             {a / 2, a * std::sqrt(3.0) / 2, 0},
             {a / 2, a * std::sqrt(3.0) / 6, a * std::sqrt(2.0 / 3.0)}};
  m.add_cell(CellKind::Tet4, {0, 1, 2, 3});
  EXPECT_NEAR(cell_volume(m, 0), a * a * a / (6 * std::sqrt(2.0)), 1e-14);
  EXPECT_NEAR(cell_min_scaled_jacobian(m, 0), 1.0, 1e-14);
}

TEST(Quality, RightPrism) {
  // Right isosceles triangle legs 1 and height 2: volume 1; corner at the 45° vertex has
  // det/lengths = sin 45°, scaled by 2/sqrt(3) (equilateral ideal) -> sqrt(2/3).
  MixedMesh m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
  m.add_cell(CellKind::Wedge6, {0, 1, 2, 3, 4, 5});
  EXPECT_NEAR(cell_volume(m, 0), 1.0, 1e-14);
  EXPECT_NEAR(cell_min_scaled_jacobian(m, 0), std::sqrt(2.0 / 3.0), 1e-14);
  // The equilateral right prism is the ideal: 1.
  MixedMesh e;
  e.nodes = {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0},
             {0, 0, 1}, {1, 0, 1}, {0.5, std::sqrt(3.0) / 2, 1}};
  e.add_cell(CellKind::Wedge6, {0, 1, 2, 3, 4, 5});
  EXPECT_NEAR(cell_volume(e, 0), std::sqrt(3.0) / 4, 1e-14);
  EXPECT_NEAR(cell_min_scaled_jacobian(e, 0), 1.0, 1e-14);
}

TEST(Quality, Pyramid) {
  // Base 2x2, apex height 1: volume 4/3. Base corner edges (2,0,0), (0,2,0), (1,1,1):
  // det 4 over 2*2*sqrt(3) = 1/sqrt(3), scaled by sqrt(2) -> sqrt(2/3).
  MixedMesh m;
  m.nodes = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}};
  m.add_cell(CellKind::Pyramid5, {0, 1, 2, 3, 4});
  EXPECT_NEAR(cell_volume(m, 0), 4.0 / 3.0, 1e-14);
  EXPECT_NEAR(cell_min_scaled_jacobian(m, 0), std::sqrt(2.0 / 3.0), 1e-14);
  // All edges equal (apex height sqrt(2)): the ideal pyramid scores 1.
  m.nodes[4] = {0, 0, std::sqrt(2.0)};
  EXPECT_NEAR(cell_min_scaled_jacobian(m, 0), 1.0, 1e-14);
  EXPECT_NEAR(cell_volume(m, 0), 4.0 * std::sqrt(2.0) / 3.0, 1e-14);
}

TEST(Quality, InvertedHexIsCounted) {
  MixedMesh m = unit_hex();
  m.nodes[6] = {0.2, 0.2, 0.2};  // top corner pushed through the bottom: corner 6 is inverted
  EXPECT_TRUE(cell_is_inverted(m, 0));
  EXPECT_LT(cell_min_scaled_jacobian(m, 0), 0.0);
  MixedMesh flipped = unit_hex();
  // Top and bottom swapped: every corner's Jacobian is negative.
  flipped.cell_nodes = {4, 5, 6, 7, 0, 1, 2, 3};
  EXPECT_TRUE(cell_is_inverted(flipped, 0));
  EXPECT_NEAR(cell_volume(flipped, 0), -1.0, 1e-14);
  EXPECT_EQ(compute_stats(flipped).inverted, 1u);
  EXPECT_EQ(compute_stats(unit_hex()).inverted, 0u);
}

TEST(Quality, FlatTetIsDegenerateNotInverted) {
  // Apex 1e-9 above the base plane: every corner Jacobian is positive (det = 1e-9 at corner 0),
  // but the scaled Jacobian is ~1e-9, so the tet counts as degenerate. At 1e-3 it is a poor but
  // usable tet.
  auto tet_at = [](double height) {
    MixedMesh m;
    m.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, height}};
    m.add_cell(CellKind::Tet4, {0, 1, 2, 3});
    return m;
  };
  const MixedMesh flat = tet_at(1e-9);
  EXPECT_FALSE(cell_is_inverted(flat, 0));
  EXPECT_TRUE(cell_is_degenerate(flat, 0));
  EXPECT_EQ(compute_stats(flat).degenerate, 1u);
  EXPECT_EQ(compute_stats(flat).inverted, 0u);
  const MixedMesh thin = tet_at(1e-3);
  EXPECT_FALSE(cell_is_degenerate(thin, 0));
  EXPECT_EQ(compute_stats(thin).degenerate, 0u);
  MixedMesh below = tet_at(-1e-9);
  EXPECT_TRUE(cell_is_inverted(below, 0));
  EXPECT_FALSE(cell_is_degenerate(below, 0));
}

TEST(Quality, HexWithSplitTopFaceIsNonConformal) {
  const MixedMesh m = testing::hex_with_split_top();
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.interior_quads, 1u);
  EXPECT_EQ(s.nonconformal_quads, 1u);
  EXPECT_NEAR(s.nc_percent, 100.0, 1e-12);
  EXPECT_TRUE(s.watertight);  // 5 hex quads + 4 outer tet triangles close the boundary
  EXPECT_EQ(s.boundary_faces_derived, 9u);
  EXPECT_NEAR(s.volume, 1.0 + 2 * (0.5 * 0.5 / 3.0), 1e-14);  // two tets of base 1/2, height 1/2
  EXPECT_NEAR(s.h_nbr, 100.0 / 3.0, 1e-12);
}

TEST(Quality, NcPercentCountsMatchedQuadsToo) {
  // Two stacked hexes (one matched interior quad) with the split top: 1 NC of 2 interior quads.
  MixedMesh m = testing::unit_hex();
  const double top[4][3] = {{0, 0, 2}, {1, 0, 2}, {1, 1, 2}, {0, 1, 2}};
  for (const auto& x : top) m.nodes.push_back({x[0], x[1], x[2]});
  m.add_cell(CellKind::Hex8, {4, 5, 6, 7, 8, 9, 10, 11});
  m.nodes.push_back({0.5, 0.5, 2.5});
  m.add_cell(CellKind::Tet4, {8, 9, 10, 12});
  m.add_cell(CellKind::Tet4, {8, 10, 11, 12});
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.interior_quads, 2u);
  EXPECT_EQ(s.nonconformal_quads, 1u);
  EXPECT_NEAR(s.nc_percent, 50.0, 1e-12);
}

TEST(Quality, OpenBoundaryIsDetected) {
  // A hex with one tet glued on a triangle of its top face only: the other half of the split
  // quad is missing, so the quad is NC but the boundary around the missing tet is open.
  MixedMesh m = testing::unit_hex();
  m.nodes.push_back({0.5, 0.5, 1.5});
  m.add_cell(CellKind::Tet4, {4, 5, 6, 8});
  EXPECT_FALSE(compute_stats(m).watertight);
}

}  // namespace
}  // namespace hexfem
