// Patch tests of the order-2 elements on multi-element meshes: the boundary nodes (mid-edge nodes
// included) get an exact elasticity solution, the interior nodes are solved from K and must
// reproduce it. Quadratic solutions (zero body force) on every mesh whose cells are affine images
// of the reference cells, distorted ones included (tets and pyramid apexes moved anywhere);
// linear solutions on distorted and curved cells of every kind. A serendipity hex20 or wedge15
// that is not affine (and any curved element) spans the quadratics in its reference coordinates,
// not in x, so for those only the linear test can be exact; the quadratic error is printed.
#include <gtest/gtest.h>

#include <cstdio>

#include "fem/element.hpp"
#include "fem_test_util.hpp"
#include "mesher/high_order_nodes.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

const Material kMat{"test", 1000.0, 0.3, 2.0};

bool on_unit_box(const Vec3& p) {
  for (double c : p)
    if (c < 1e-9 || c > 1 - 1e-9) return true;
  return false;
}

// Displacement fields with μΔu + (λ+μ)∇div u = 0: a linear part plus (optionally) gradients of
// harmonic cubics and divergence-free harmonic quadratics.
struct Field {
  double c0[3], G[3][3], q[6];
  Vec3 operator()(const Vec3& p) const {
    const double x = p[0], y = p[1], z = p[2];
    Vec3 u;
    for (int a = 0; a < 3; ++a) u[a] = c0[a] + G[a][0] * x + G[a][1] * y + G[a][2] * z;
    u[0] += q[0] * y * z + q[3] * (3 * x * x - 3 * y * y) + q[5] * (-6 * z * x);
    u[1] += q[1] * z * x + q[3] * (-6 * x * y) + q[4] * (3 * y * y - 3 * z * z);
    u[2] += q[2] * x * y + q[4] * (-6 * y * z) + q[5] * (3 * z * z - 3 * x * x);
    return u;
  }
};

Field random_field(bool quadratic, std::mt19937& rng) {
  std::uniform_real_distribution<double> r(-1e-3, 1e-3);
  Field f{};
  for (int a = 0; a < 3; ++a) {
    f.c0[a] = r(rng);
    for (int b = 0; b < 3; ++b) f.G[a][b] = r(rng);
  }
  for (double& c : f.q) c = quadratic ? r(rng) : 0.0;
  return f;
}

// Max |u_h - u| / max |u| at the nodes after solving the interior from the boundary values.
double patch_error(const MixedMesh& mesh, const std::vector<bool>& boundary, const Field& field) {
  const DofMap dofs = number_free_dofs(mesh, std::vector<std::uint8_t>(3 * mesh.nodes.size(), 0));
  const SystemMatrices sys = assemble_system(mesh, kMat, dofs);
  const Eigen::MatrixXd K = test::dense_full(sys.K);
  std::vector<int> I, B;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(dofs.num_free), exact = u;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    for (int a = 0; a < 3; ++a) {
      const int d = dofs.dof[3 * v + a];
      exact[d] = field(mesh.nodes[v])[a];
      (boundary[v] ? B : I).push_back(d);
      if (boundary[v]) u[d] = exact[d];
    }
  EXPECT_FALSE(I.empty());
  Eigen::MatrixXd KII(I.size(), I.size());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(I.size());
  for (std::size_t i = 0; i < I.size(); ++i) {
    for (std::size_t j = 0; j < I.size(); ++j) KII(i, j) = K(I[i], I[j]);
    for (int b : B) rhs[i] -= K(I[i], b) * u[b];
  }
  const Eigen::VectorXd uI = KII.ldlt().solve(rhs);
  for (std::size_t i = 0; i < I.size(); ++i) u[I[i]] = uI[i];
  return (u - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
}

// Box mesh of the unit cube at order 2, interior corners moved by `corner_move` when `move`
// selects them, interior mid-edge nodes by `curve`, then the whole mesh mapped by a random
// affine map (every cell stays affine if it was).
struct Patch {
  MixedMesh mesh;
  std::vector<bool> boundary;
};
Patch make_patch(CellKind kind, double corner_move, double curve, std::mt19937& rng,
                 bool centres_only = false) {
  Patch p;
  p.mesh = make_box_mesh({1, 1, 1}, 3, 3, 3, kind);
  const std::size_t lattice = 4 * 4 * 4;
  std::uniform_real_distribution<double> u(-1, 1);
  for (std::size_t v = 0; v < p.mesh.nodes.size(); ++v)
    if (!on_unit_box(p.mesh.nodes[v]) && (!centres_only || v >= lattice))
      for (double& c : p.mesh.nodes[v]) c += corner_move * u(rng);
  const std::size_t corners = p.mesh.nodes.size();
  add_mid_edge_nodes(p.mesh);
  for (std::size_t v = corners; v < p.mesh.nodes.size(); ++v)
    if (!on_unit_box(p.mesh.nodes[v]))
      for (double& c : p.mesh.nodes[v]) c += curve * u(rng);
  for (const Vec3& x : p.mesh.nodes) p.boundary.push_back(on_unit_box(x));
  p.mesh.nodes = test::affine_image(p.mesh.nodes, rng);
  for (std::size_t c = 0; c < p.mesh.num_cells(); ++c)
    EXPECT_GT(element_jacobian_ratio(p.mesh, c), 0.05) << kind_name(kind, 2) << " cell " << c;
  return p;
}

TEST(Order2Patch, QuadraticSolutionsExactOnAffineCells) {
  std::mt19937 rng(21);
  for (CellKind kind : test::kAllKinds) {
    const Patch p = make_patch(kind, 0, 0, rng);
    const double err = patch_error(p.mesh, p.boundary, random_field(true, rng));
    EXPECT_LT(err, 1e-10) << kind_name(kind, 2);
    std::printf("order-2 patch %-9s affine, quadratic field: max error %.1e\n", kind_name(kind, 2),
                err);
  }
}

TEST(Order2Patch, QuadraticSolutionsExactOnDistortedAffineCells) {
  std::mt19937 rng(22);
  // Tets: every interior corner moved (each tet stays straight, so affine).
  Patch p = make_patch(CellKind::Tet4, 0.1, 0, rng);
  double err = patch_error(p.mesh, p.boundary, random_field(true, rng));
  EXPECT_LT(err, 1e-10) << "tet10 distorted";
  std::printf("order-2 patch tet10 distorted, quadratic field: max error %.1e\n", err);
  // Pyramids (with tets): the apexes at the cube centres moved (square bases: still affine).
  p = make_patch(CellKind::Pyramid5, 0.1, 0, rng, true);
  err = patch_error(p.mesh, p.boundary, random_field(true, rng));
  EXPECT_LT(err, 1e-10) << "pyramid13 distorted";
  std::printf("order-2 patch pyramid13 distorted apexes, quadratic field: max error %.1e\n", err);
}

TEST(Order2Patch, LinearSolutionsExactOnDistortedCurvedCells) {
  std::mt19937 rng(23);
  for (CellKind kind : test::kAllKinds) {
    const double s = kind == CellKind::Pyramid5 ? 0.5 : 1.0;  // its cells are half as tall
    const Patch p = make_patch(kind, 0.06 * s, 0.02 * s, rng);
    const double lin = patch_error(p.mesh, p.boundary, random_field(false, rng));
    EXPECT_LT(lin, 1e-10) << kind_name(kind, 2);
    const double quad = patch_error(p.mesh, p.boundary, random_field(true, rng));
    std::printf("order-2 patch %-9s distorted+curved: linear field %.1e, quadratic field %.1e\n",
                kind_name(kind, 2), lin, quad);
  }
}

}  // namespace
}  // namespace hexfem
