// Curving the boundary of an order-2 mesh: a thin tet whose boundary face bulges into it is
// inverted by the curving; bend_interior_nodes makes it valid again by moving its interior
// mid-edge nodes (the boundary ones stay on the geometry), and a bulge deeper than the tet is
// left to straighten_invalid_cells. Checked with the solver's own Jacobian test and a hand
// computation of det J at the corner.
#include <gtest/gtest.h>

#include <vector>

#include "fem/element.hpp"
#include "mesher/high_order_nodes.hpp"
#include "mesher/mesh/element_topology.hpp"

namespace hexfem {
namespace {

constexpr double kMin = 1e-3;

// One tet over the triangle (0,0,0), (1,0,0), (0,1,0) on the boundary, apex (0.3, 0.3, 0.5);
// the boundary mid-edge nodes lifted by `lift` towards the apex (a concave surface seen from
// the solid).
MixedMesh lifted_tet(double lift) {
  MixedMesh m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 0.5}};
  m.add_cell(CellKind::Tet4, {0, 1, 2, 3});
  m.add_bface(0, 2, 1, -1, 1);
  add_mid_edge_nodes(m, [lift](const Vec3& a, const Vec3& b, int, int) {
    return Vec3{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, lift};
  });
  return m;
}

Order2Report bend(MixedMesh& m) {
  Order2Report r;
  bend_interior_nodes(m, element_jacobian_ratio, element_jacobian_ratio_at_nodes_and_points, kMin,
                      &r);
  return r;
}

std::vector<std::int32_t> boundary_nodes(const MixedMesh& m) {
  std::vector<std::int32_t> out;
  for (const std::int32_t n : m.bface_edge_nodes)
    if (n >= 0) out.push_back(n);
  return out;
}

TEST(Order2Curving, BendsTheInteriorNodesOfATetItsCurvedFaceInverts) {
  // The face rises to 0.33 under the apex, 0.5 high: room for the tet to follow it.
  MixedMesh m = lifted_tet(0.25);
  // By hand: at corner 0 the curved edges leave along (1, 0, 1) and (0, 1, 1), the straight one
  // along (0.3, 0.3, 0.5): det = 0.5 - 0.3 - 0.3 < 0.
  ASSERT_LT(element_jacobian_ratio(m, 0), 0);
  const MixedMesh curved = m;
  Order2Report r = bend(m);
  EXPECT_EQ(r.bent_cells, 1);
  EXPECT_GE(r.bent_nodes, 1);
  EXPECT_GE(element_jacobian_ratio(m, 0), kMin);
  for (const std::int32_t n : boundary_nodes(m)) EXPECT_EQ(m.nodes[n], curved.nodes[n]);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(m.nodes[v], curved.nodes[v]);
  // Nothing left to straighten: the face keeps its curve.
  straighten_invalid_cells(m, element_jacobian_ratio, kMin, &r);
  EXPECT_EQ(r.straightened_cells, 0);
  for (const std::int32_t n : boundary_nodes(m)) EXPECT_EQ(m.nodes[n], curved.nodes[n]);
}

TEST(Order2Curving, ABulgeDeeperThanTheCellIsLeftToStraightening) {
  MixedMesh m = lifted_tet(0.45);  // the face rises to 0.59 under the apex, 0.5 high
  ASSERT_LT(element_jacobian_ratio(m, 0), 0);
  const MixedMesh curved = m;
  Order2Report r = bend(m);
  EXPECT_EQ(r.bent_cells, 0);
  for (std::size_t n = 0; n < m.nodes.size(); ++n) EXPECT_EQ(m.nodes[n], curved.nodes[n]) << n;
  straighten_invalid_cells(m, element_jacobian_ratio, kMin, &r);
  EXPECT_EQ(r.straightened_cells, 1);
  EXPECT_NEAR(element_jacobian_ratio(m, 0), 1.0, 1e-12);  // a straight tet: det J constant
}

TEST(Order2Curving, AValidCurvedCellIsLeftAlone) {
  MixedMesh m = lifted_tet(-0.1);  // bulging away from the apex: distorted, not inverted
  const double before = element_jacobian_ratio(m, 0);
  ASSERT_GT(before, kMin);
  ASSERT_LT(before, 0.9);
  const MixedMesh curved = m;
  Order2Report r = bend(m);
  straighten_invalid_cells(m, element_jacobian_ratio, kMin, &r);
  EXPECT_EQ(r.bent_cells + r.straightened_cells, 0);
  for (std::size_t n = 0; n < m.nodes.size(); ++n) EXPECT_EQ(m.nodes[n], curved.nodes[n]) << n;
}

}  // namespace
}  // namespace hexfem
