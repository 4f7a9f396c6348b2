// make_conformal on hand-built meshes: a unit hex whose bottom face is NC against the cells
// below it. Expected counts and volumes are worked out by hand for each case.
#include <gtest/gtest.h>

#include <vector>

#include "mesher/conformal.hpp"
#include "mesher/mesh/conformity.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {
namespace {

constexpr int kHex = static_cast<int>(CellKind::Hex8), kPyr = static_cast<int>(CellKind::Pyramid5),
              kTet = static_cast<int>(CellKind::Tet4);

// The unit hex [0,1]^3: nodes 0..7 (bottom a=0 (0,0,0), b=1 (1,0,0), c=2 (1,1,0), e=3 (0,1,0)).
MixedMesh unit_hex() {
  MixedMesh m;
  for (double z : {0.0, 1.0}) {
    m.nodes.push_back({0, 0, z});
    m.nodes.push_back({1, 0, z});
    m.nodes.push_back({1, 1, z});
    m.nodes.push_back({0, 1, z});
  }
  m.add_cell(CellKind::Hex8, {0, 1, 2, 3, 4, 5, 6, 7});
  return m;
}

std::int32_t add_node(MixedMesh& m, const Vec3& x) {
  m.nodes.push_back(x);
  return static_cast<std::int32_t>(m.nodes.size() - 1);
}

// A tet given in either orientation, stored positive.
void add_tet(MixedMesh& m, std::int32_t p, std::int32_t q, std::int32_t r, std::int32_t s) {
  const Vec3 x[4] = {m.nodes[p], m.nodes[q], m.nodes[r], m.nodes[s]};
  if (min_scaled_jacobian(CellKind::Tet4, x) < 0) std::swap(q, r);
  m.add_cell(CellKind::Tet4, {p, q, r, s});
}

double total_volume(const MixedMesh& m) {
  double v = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) v += cell_volume(m, c);
  return v;
}

// What every case checks after the pass: no NC quad left (counted from the faces, not the
// report), no cell inverted or flat, a closed boundary, the region's volume kept.
void expect_conformal_and_valid(const MixedMesh& m, double volume) {
  EXPECT_EQ(count_quad_faces(m).nonconformal, 0u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.inverted, 0u);
  EXPECT_EQ(s.degenerate, 0u);
  EXPECT_TRUE(s.watertight) << s.open_boundary_edges << " open boundary edges";
  EXPECT_NEAR(total_volume(m), volume, 1e-12);
}

TEST(Conformal, TwoTetsSharingAnApexBecomeThePyramid) {
  // The lower cube's Kuhn tets on the hex's bottom diagonal (0,0,0)-(1,1,0): both contain
  // (0,0,-1), so with the quad they are the pyramid of height 1 (volume 1/3).
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {0, 0, -1});
  add_tet(m, p, 0, 1, 2);
  add_tet(m, p, 0, 3, 2);
  flag_nonconformal_quads(m);
  ASSERT_EQ(m.nc_cell.size(), 1u);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.nc_before, 1u);
  EXPECT_EQ(r.nc_after, 0u);
  EXPECT_EQ(r.pyramids, 1u);
  EXPECT_EQ(r.shell_pyramids, 1u);
  EXPECT_EQ(r.steiner_points, 0u);
  EXPECT_EQ(m.nodes.size(), 9u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 1u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 1u);
  EXPECT_EQ(s.cells_per_kind[kTet], 0u);
  expect_conformal_and_valid(m, 1.0 + 1.0 / 3);
}

TEST(Conformal, ThreeTetShellGetsAPyramidAndSixTetsAroundANewNode) {
  // Tets (a,c,b,P), (a,c,P,R), (a,c,R,e) around the diagonal a-c below the hex: no apex is
  // shared, so a new node s fills the shell: the pyramid on the quad, (a,u,w,s) and (c,u,w,s)
  // for each tet. The hex stays.
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {0.75, 0.25, -0.5});
  const std::int32_t q = add_node(m, {0.25, 0.75, -0.5});
  add_tet(m, 0, 2, 1, p);
  add_tet(m, 0, 2, p, q);
  add_tet(m, 0, 2, q, 3);
  flag_nonconformal_quads(m);
  ASSERT_EQ(m.nc_cell.size(), 1u);
  const double volume = total_volume(m);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.pyramids, 1u);
  EXPECT_EQ(r.shell_pyramids, 0u);
  EXPECT_EQ(r.steiner_points, 1u);
  EXPECT_EQ(r.failed, 0u);
  EXPECT_EQ(m.nodes.size(), 11u);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 1u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 1u);
  EXPECT_EQ(s.cells_per_kind[kTet], 6u);
  EXPECT_DOUBLE_EQ(r.hex_volume_after, 1.0);
  expect_conformal_and_valid(m, volume);
}

TEST(Conformal, AHexWithAPyramidAcrossItsDiagonalIsSplitAboutItsCentre) {
  // Under the bottom face: the tet (a,b,c,P) and a pyramid whose side (c,a,e) holds the
  // diagonal a-c, so no tet shell can be filled there: the hex goes, split about a new node
  // into two tets on its bottom (the far side's triangles) and five pyramids on its other
  // faces. Volumes by hand: hex 1, tet 1/6, pyramid 1/3 (base sqrt(2) x 1, height 1/sqrt(2)).
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {1, 0, -1});
  const std::int32_t x = add_node(m, {0, 0, -1});
  const std::int32_t y = add_node(m, {1, 1, -1});
  add_tet(m, 0, 1, 2, p);
  {
    std::int32_t pyr[5] = {0, x, y, 2, 3};
    const Vec3 c[5] = {m.nodes[0], m.nodes[x], m.nodes[y], m.nodes[2], m.nodes[3]};
    if (min_scaled_jacobian(CellKind::Pyramid5, c) < 0) std::swap(pyr[1], pyr[3]);
    m.add_cell(CellKind::Pyramid5, pyr);
  }
  flag_nonconformal_quads(m);
  ASSERT_EQ(m.nc_cell.size(), 1u);
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.cells_split[kHex], 1u);
  EXPECT_EQ(r.steiner_points, 1u);
  EXPECT_DOUBLE_EQ(r.hex_volume_before, 1.0);
  EXPECT_DOUBLE_EQ(r.hex_volume_after, 0.0);
  const MeshStats s = compute_stats(m);
  EXPECT_EQ(s.cells_per_kind[kHex], 0u);
  EXPECT_EQ(s.cells_per_kind[kPyr], 6u);
  EXPECT_EQ(s.cells_per_kind[kTet], 3u);
  expect_conformal_and_valid(m, 1.0 + 1.0 / 6 + 1.0 / 3);
}

TEST(Conformal, AConformalMeshIsLeftAlone) {
  MixedMesh m = unit_hex();
  const std::int32_t p = add_node(m, {0.5, 0.5, -0.5});
  m.add_cell(CellKind::Pyramid5, {0, 3, 2, 1, p});  // apex below: base seen from it
  flag_nonconformal_quads(m);
  const std::vector<std::int32_t> before = m.cell_nodes;
  const ConformalReport r = make_conformal(m);
  EXPECT_EQ(r.nc_before, 0u);
  EXPECT_EQ(m.cell_nodes, before);
}

}  // namespace
}  // namespace hexfem
