// lift_slivers: a flat or sliver cell left at the end is improved by moving one interior
// vertex, and only interior vertices move.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "mesher/mesh/quality.hpp"
#include "mesher/volume_slivers.hpp"

namespace hexfem {
namespace {

// The unit cube's 12 boundary triangles coned to node 8 at p: 12 tets, oriented positively
// for p at the centre.
MixedMesh cube_cone(const Vec3& p) {
  MixedMesh m;
  for (int i = 0; i < 8; ++i)
    m.nodes.push_back({double(i & 1), double((i >> 1) & 1), double(i >> 2)});
  m.nodes.push_back({0.5, 0.5, 0.5});
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    for (const std::array<int, 3> t : {std::array<int, 3>{q[0], q[1], q[2]}, {q[0], q[2], q[3]}}) {
      std::array<std::int32_t, 4> tet = {t[0], t[1], t[2], 8};
      // Positive orientation: det(b - a, c - a, p - a) > 0, by hand.
      const Vec3 &a = m.nodes[tet[0]], &b = m.nodes[tet[1]], &c = m.nodes[tet[2]],
                 &apex = m.nodes[8];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double w[3] = {apex[0] - a[0], apex[1] - a[1], apex[2] - a[2]};
      const double det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                         u[2] * (v[0] * w[1] - v[1] * w[0]);
      if (det < 0) std::swap(tet[1], tet[2]);
      m.add_cell(CellKind::Tet4, tet.data());
    }
  m.nodes[8] = p;
  return m;
}

double min_sj(const MixedMesh& m) {
  double s = 1;
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    s = std::min(s, cell_is_inverted(m, c) ? -1.0 : cell_min_scaled_jacobian(m, c));
  return s;
}

TEST(LiftSlivers, FlatCellNearAFaceIsMovedInside) {
  MixedMesh m = cube_cone({0.3, 0.3, 1e-9});  // the two tets over the face z = 0 are flat
  ASSERT_LT(min_sj(m), kDegenerateScaledJacobian);
  const auto corners = std::vector<Vec3>(m.nodes.begin(), m.nodes.begin() + 8);
  EXPECT_GE(lift_slivers(m, 8, 0.02), 1u);
  EXPECT_GE(min_sj(m), 0.02);
  EXPECT_EQ(std::vector<Vec3>(m.nodes.begin(), m.nodes.begin() + 8), corners);
}

TEST(LiftSlivers, ASliverIsRaisedAndGoodCellsAreLeftAlone) {
  MixedMesh m = cube_cone({0.3, 0.3, 0.004});
  const double before = min_sj(m);
  ASSERT_GT(before, kDegenerateScaledJacobian);
  ASSERT_LT(before, 0.02);
  EXPECT_GE(lift_slivers(m, 8, 0.02), 1u);
  EXPECT_GT(min_sj(m), 2 * before);
  MixedMesh good = cube_cone({0.5, 0.5, 0.5});  // nothing below the bound: nothing moves
  const auto nodes = good.nodes;
  EXPECT_EQ(lift_slivers(good, 8, 0.02), 0u);
  EXPECT_EQ(good.nodes, nodes);
}

TEST(LiftSlivers, FixedVerticesNeverMove) {
  MixedMesh m = cube_cone({0.3, 0.3, 1e-9});
  const auto before = m.nodes;
  EXPECT_EQ(lift_slivers(m, 9, 0.02), 0u);  // node 8 counts as a surface node here
  EXPECT_EQ(m.nodes, before);
}

}  // namespace
}  // namespace hexfem
