// Validity of curved order-2 cells, and curving the boundary of an order-2 mesh. The check:
// shape derivatives are finite at every node (hex20's were 0/0 on its faces, so its corners
// were silently skipped), and the Bernstein lower bound of det J (tet10, hex20) lies below det J
// everywhere, exactly on an affine cell. The curving: a thin tet whose boundary face bulges
// into it is inverted by the curving; bend_interior_nodes makes it valid again by moving its
// interior mid-edge nodes (the boundary ones stay on the geometry), and a bulge deeper than the
// tet is left to straighten_invalid_cells, which takes back only as much of it as needed.
// Checked with the solver's own Jacobian test and a hand computation of det J at the corner.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fem/element.hpp"
#include "fem/jacobian_bounds.hpp"
#include "mesher/high_order_nodes.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/structured_box.hpp"

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
  EXPECT_GE(element_jacobian_ratio(m, 0), kMin);
  // Only as much of the bulge taken back as that needs: the face's nodes between the chord
  // (z = 0) and where the geometry put them (0.45), below the apex (0.5).
  for (const std::int32_t n : boundary_nodes(m)) {
    EXPECT_GT(m.nodes[n][2], 0.05) << n;
    EXPECT_LT(m.nodes[n][2], 0.45) << n;
  }
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

// det J at reference point xi of the order-2 cell made of `nodes`.
double det_at(CellKind kind, const std::vector<Vec3>& nodes, const Vec3& xi) {
  ShapeValues s;
  shape_functions(kind, 2, xi, s);
  return jacobian_determinant(s, nodes.data());
}

MixedMesh one_cell(CellKind kind, const std::vector<Vec3>& nodes) {
  MixedMesh m;
  m.nodes = nodes;
  std::vector<std::int32_t> corners;
  for (int i = 0; i < num_nodes(kind); ++i) corners.push_back(i);
  m.add_cell(kind, corners.data());
  m.order = 2;
  m.cell_edge_nodes.assign(kMaxCellEdges, -1);
  for (int e = 0; e < num_edges(kind); ++e) m.cell_edge_nodes[e] = num_nodes(kind) + e;
  return m;
}

TEST(Order2Curving, ShapeDerivativesAreFiniteAtEveryNode) {
  for (const CellKind kind : {CellKind::Tet4, CellKind::Pyramid5, CellKind::Wedge6, CellKind::Hex8})
    for (Vec3 p : reference_nodes(kind, 2)) {
      if (kind == CellKind::Pyramid5 && p[2] == 1) p[2] = 0.99;  // 0/0 at the apex itself
      ShapeValues s;
      shape_functions(kind, 2, p, s);
      for (int i = 0; i < s.n; ++i)
        for (int d = 0; d < 3; ++d)
          EXPECT_TRUE(std::isfinite(s.dN[i][d])) << kind_name(kind, 2) << " node " << i;
    }
}

TEST(Order2Curving, BernsteinBoundIsBelowDetJEverywhereAndExactWhenAffine) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const CellKind kind : {CellKind::Tet4, CellKind::Hex8}) {
    const std::vector<Vec3> ref = reference_nodes(kind, 2);
    // An affine image (det J = 6 everywhere): the bound is that constant.
    std::vector<Vec3> affine;
    for (const Vec3& x : ref) affine.push_back({2 * x[0] + x[1], 3 * x[1], x[2] + 0.5 * x[0]});
    const auto exact = order2_jacobian_bound(kind, affine.data());
    ASSERT_TRUE(exact.has_value());
    EXPECT_NEAR(exact->lower, 6.0, 1e-10) << kind_name(kind, 2);
    EXPECT_NEAR(exact->max_det, 6.0, 1e-10) << kind_name(kind, 2);
    // Every node moved at random by up to 0.15: the bound never exceeds det J at 20,000 points.
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<Vec3> nodes;
      for (const Vec3& x : ref)
        nodes.push_back({x[0] + 0.15 * u(rng), x[1] + 0.15 * u(rng), x[2] + 0.15 * u(rng)});
      const auto bound = order2_jacobian_bound(kind, nodes.data());
      double lowest = 1e300;
      for (int k = 0; k < 20000; ++k) {
        Vec3 xi{u(rng), u(rng), u(rng)};
        if (kind == CellKind::Tet4) {
          for (double& c : xi) c = (c + 1) / 2;
          if (xi[0] + xi[1] + xi[2] > 1) continue;
        }
        lowest = std::min(lowest, det_at(kind, nodes, xi));
      }
      EXPECT_LE(bound->lower, lowest + 1e-12) << kind_name(kind, 2) << " trial " << trial;
      EXPECT_GT(bound->lower, lowest - 0.2) << kind_name(kind, 2) << " trial " << trial;
    }
  }
}

// A hex20 whose mid-edge node on edge 0-1 sits a fifth of the way from corner 0: the edge runs
// backwards at that corner (tangent 4 m - 3 x0 - x1 = -0.2 (x1 - x0)), det J < 0 there and only
// there. The corner itself is a node of the check; its derivatives used to be 0/0 (NaN), which
// the min/max skipped, so the cell passed.
TEST(Order2Curving, AHex20FoldedAtACornerIsInverted) {
  std::vector<Vec3> nodes = reference_nodes(CellKind::Hex8, 2);
  const Vec3 x0 = nodes[0], x1 = nodes[1];
  const int m01 = 8 + 0;  // edges_of(Hex8)[0] is 0-1
  ASSERT_EQ(edges_of(CellKind::Hex8)[0][0] + edges_of(CellKind::Hex8)[0][1], 1);
  for (int d = 0; d < 3; ++d) nodes[m01][d] = x0[d] + 0.2 * (x1[d] - x0[d]);
  const MixedMesh m = one_cell(CellKind::Hex8, nodes);
  EXPECT_LT(det_at(CellKind::Hex8, nodes, {-1, -1, -1}), 0);
  EXPECT_LT(element_jacobian_ratio_at_nodes_and_points(m, 0), 0);
  EXPECT_LT(element_jacobian_ratio(m, 0), 0);
}

// Boxes of tets and of hexes whose boundary mid-edge nodes are pushed off their faces by up to
// 0.7 of a cell, in or out (a fixed pseudo-random pattern): some cells are bent, some
// straightened. The steps keep every cell's ratio current when asked to (so that each pass need
// not measure every cell again): the same nodes as without, and at the end the ratio of every
// cell as element_jacobian_ratio finds it afresh.
TEST(Order2Curving, TheRatiosKeptThroughTheStepsAreTheCellsRatios) {
  for (const CellKind kind : {CellKind::Tet4, CellKind::Hex8}) {
    const double cell = 0.25;
    MixedMesh m = make_box_mesh({1, 1, 1}, 4, 4, 4, kind);
    add_mid_edge_nodes(m, [cell](const Vec3& a, const Vec3& b, int f, int) {
      Vec3 mid{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
      const auto h =
          static_cast<std::uint32_t>(std::lround(1e3 * (mid[0] + 3 * mid[1] + 7 * mid[2])));
      const double push = 0.7 * cell * (static_cast<double>(h * 2654435761u % 1000) / 500 - 1);
      mid[(f - 1) / 2] += push;  // along the face's normal (faces 1..6: x, x, y, y, z, z)
      return mid;
    });
    MixedMesh plain = m;
    std::vector<double> ratios;
    Order2Report r, rp;
    bend_interior_nodes(m, element_jacobian_ratio, element_jacobian_ratio_at_nodes_and_points, kMin,
                        &r, &ratios);
    straighten_invalid_cells(m, element_jacobian_ratio, kMin, &r, &ratios);
    bend_interior_nodes(plain, element_jacobian_ratio, element_jacobian_ratio_at_nodes_and_points,
                        kMin, &rp);
    straighten_invalid_cells(plain, element_jacobian_ratio, kMin, &rp);
    // Tets are bent and straightened; hexes only straightened (their interior nodes cannot
    // lift a corner folded by two curved edges of a face).
    EXPECT_GT(r.straightened_cells, 0) << kind_name(kind, 2);
    if (kind == CellKind::Tet4) {
      EXPECT_GT(r.bent_cells, 0);
    }
    EXPECT_EQ(r.bent_cells, rp.bent_cells);
    EXPECT_EQ(r.straightened_cells, rp.straightened_cells);
    EXPECT_EQ(m.nodes, plain.nodes) << kind_name(kind, 2);
    ASSERT_EQ(ratios.size(), m.num_cells());
    for (std::size_t c = 0; c < m.num_cells(); ++c)
      EXPECT_EQ(ratios[c], element_jacobian_ratio(m, c)) << kind_name(kind, 2) << " cell " << c;
  }
}

// The unit cube as a hex20 with the mid-edge nodes of its top face raised by d: the top becomes
// the quad8 surface z = 1 + d (sum of the four mid-edge functions), each of which integrates to
// a third of the face, so by hand V = 1 + 4d/3 (the straight cube: 1).
TEST(Order2Curving, AHex20WithARaisedTopHasTheVolumeWorkedOutByHand) {
  std::vector<Vec3> nodes = reference_nodes(CellKind::Hex8, 2);
  for (Vec3& p : nodes)
    for (double& c : p) c = (c + 1) / 2;
  MixedMesh m = one_cell(CellKind::Hex8, nodes);
  EXPECT_NEAR(mesh_volume(m), 1, 1e-14);
  const double d = 0.1;
  int raised = 0;
  for (std::size_t i = 8; i < nodes.size(); ++i)
    if (nodes[i][2] == 1) {
      m.nodes[i][2] += d;
      ++raised;
    }
  ASSERT_EQ(raised, 4);
  EXPECT_NEAR(mesh_volume(m), 1 + 4 * d / 3, 1e-14);
  EXPECT_NEAR(element_volume(m, 0), 1 + 4 * d / 3, 1e-14);
}

}  // namespace
}  // namespace hexfem
