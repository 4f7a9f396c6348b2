// Patch tests on multi-element meshes: boundary nodes get a linear displacement field, the
// interior nodes are solved from K; they must reproduce the field and every element's stress
// must equal the exact constant stress. Undistorted and distorted, every element kind.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "fem/element.hpp"
#include "fem_test_util.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

const Material kMat{"test", 1000.0, 0.3, 2.0};

// One cube split into six pyramids on its faces, apex at an interior node: a pure-pyramid patch.
MixedMesh pyramid_cube() {
  MixedMesh m;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) m.nodes.push_back({double(i), double(j), double(k)});
  m.nodes.push_back({0.5, 0.5, 0.5});
  const auto v = [](int i, int j, int k) { return i + 2 * j + 4 * k; };
  // Each base written in some order; mirrored below where that order is clockwise from the apex.
  m.add_cell(CellKind::Pyramid5, {v(0, 0, 0), v(0, 1, 0), v(1, 1, 0), v(1, 0, 0), 8});
  m.add_cell(CellKind::Pyramid5, {v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1), 8});
  m.add_cell(CellKind::Pyramid5, {v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1), 8});
  m.add_cell(CellKind::Pyramid5, {v(0, 1, 0), v(0, 1, 1), v(1, 1, 1), v(1, 1, 0), 8});
  m.add_cell(CellKind::Pyramid5, {v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0), 8});
  m.add_cell(CellKind::Pyramid5, {v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1), 8});
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    if (cell_is_inverted(m, c)) std::swap(m.cell_nodes[8 * c + 1], m.cell_nodes[8 * c + 3]);
  return m;
}

// Interior = nodes that are on no box side (lattice coordinates strictly inside).
std::vector<bool> interior_nodes(const MixedMesh& m, double lo, double hi) {
  std::vector<bool> in(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    bool inside = true;
    for (double c : m.nodes[i]) inside = inside && c > lo + 1e-9 && c < hi - 1e-9;
    in[i] = inside;
  }
  return in;
}

void patch_test(MixedMesh mesh, const std::string& label, bool distort, std::uint32_t seed) {
  const std::vector<bool> interior = interior_nodes(mesh, 0.0, 1.0);
  int n_interior = 0;
  for (bool b : interior) n_interior += b;
  ASSERT_GT(n_interior, 0) << label;
  std::mt19937 rng(seed);
  if (distort) test::perturb(mesh.nodes, 0.04, rng);  // every node, boundary included (h >= 1/3)
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    ASSERT_FALSE(cell_is_inverted(mesh, c)) << label;
  std::uniform_real_distribution<double> rnd(-1e-3, 1e-3);
  double G[3][3], c0[3];
  for (int a = 0; a < 3; ++a) {
    c0[a] = rnd(rng);
    for (int b = 0; b < 3; ++b) G[a][b] = rnd(rng);
  }
  const auto field = [&](const Vec3& p, int a) {
    return c0[a] + G[a][0] * p[0] + G[a][1] * p[1] + G[a][2] * p[2];
  };

  // Full K (nothing fixed), then K_II u_I = -K_IB u_B.
  const DofMap dofs = number_free_dofs(mesh, std::vector<std::uint8_t>(3 * mesh.nodes.size(), 0));
  const SystemMatrices sys = assemble_system(mesh, kMat, dofs);
  const Eigen::MatrixXd K = test::dense_full(sys.K);
  std::vector<int> I, B;
  Eigen::VectorXd uB_all = Eigen::VectorXd::Zero(dofs.num_free);
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    for (int a = 0; a < 3; ++a) {
      const int d = dofs.dof[3 * v + a];
      (interior[v] ? I : B).push_back(d);
      if (!interior[v]) uB_all[d] = field(mesh.nodes[v], a);
    }
  Eigen::MatrixXd KII(I.size(), I.size());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(I.size());
  for (std::size_t i = 0; i < I.size(); ++i) {
    for (std::size_t j = 0; j < I.size(); ++j) KII(i, j) = K(I[i], I[j]);
    for (int b : B) rhs[i] -= K(I[i], b) * uB_all[b];
  }
  const Eigen::VectorXd uI = KII.ldlt().solve(rhs);
  Eigen::VectorXd u = uB_all;
  for (std::size_t i = 0; i < I.size(); ++i) u[I[i]] = uI[i];

  double max_err = 0;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    for (int a = 0; a < 3; ++a)
      max_err = std::max(max_err, std::abs(u[dofs.dof[3 * v + a]] - field(mesh.nodes[v], a)));
  EXPECT_LT(max_err, 1e-13) << label << ": interior displacement error";

  // Stress error: D (ε - ε_exact) at every quadrature point of every element.
  const double exact[6] = {G[0][0],           G[1][1],           G[2][2],
                           G[0][1] + G[1][0], G[1][2] + G[2][1], G[2][0] + G[0][2]};
  const double lam = kMat.lambda(), mu = kMat.mu();
  const double ref_stress = (lam + 2 * mu) * 3e-3;
  double max_stress_err = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const ReferenceElement& ref = reference_element(mesh.cell_kind[c]);
    std::vector<Vec3> x;
    std::vector<double> ue;
    for (int i = 0; i < ref.n; ++i) {
      const std::int32_t v = mesh.cell(c)[i];
      x.push_back(mesh.nodes[v]);
      for (int a = 0; a < 3; ++a) ue.push_back(u[dofs.dof[3 * v + a]]);
    }
    for (const auto& eps : element_strains(ref, x.data(), ue.data())) {
      double d[6];
      for (int k = 0; k < 6; ++k) d[k] = eps[k] - exact[k];
      const double tr = d[0] + d[1] + d[2];
      const double s[6] = {lam * tr + 2 * mu * d[0],
                           lam * tr + 2 * mu * d[1],
                           lam * tr + 2 * mu * d[2],
                           mu * d[3],
                           mu * d[4],
                           mu * d[5]};
      for (double si : s) max_stress_err = std::max(max_stress_err, std::abs(si));
    }
  }
  EXPECT_LT(max_stress_err, 1e-10 * ref_stress) << label << ": stress error";
  std::printf(
      "patch %-22s interior nodes %3d: max |u - u_exact| %.1e (|u| ~ 1e-3), max stress error / "
      "stress %.1e\n",
      label.c_str(), n_interior, max_err, max_stress_err / ref_stress);
}

TEST(PatchTest, EveryKindUndistortedAndDistorted) {
  std::uint32_t seed = 1;
  for (CellKind kind : test::kAllKinds)
    for (bool distort : {false, true})
      patch_test(make_box_mesh({1, 1, 1}, 3, 3, 3, kind),
                 std::string(kind_name(kind)) + (distort ? " distorted" : ""), distort, seed++);
}

TEST(PatchTest, PurePyramidCube) {
  for (bool distort : {false, true})
    patch_test(pyramid_cube(), distort ? "pyramids distorted" : "pyramids", distort, 99);
}

TEST(PatchTest, AssembledMassIsRhoV) {
  for (CellKind kind : test::kAllKinds) {
    const MixedMesh mesh = make_box_mesh({2, 1, 0.5}, 3, 2, 2, kind);
    const DofMap dofs = number_free_dofs(mesh, std::vector<std::uint8_t>(3 * mesh.nodes.size(), 0));
    const SystemMatrices sys = assemble_system(mesh, kMat, dofs);
    // Σ of all entries of the full M = 3 ρ V.
    const double sum = test::dense_full(sys.M).sum();
    EXPECT_NEAR(sum, 3 * kMat.rho * 1.0, 1e-12) << kind_name(kind);
    EXPECT_NEAR(sys.mass, kMat.rho * 1.0, 1e-12) << kind_name(kind);
  }
}

}  // namespace
}  // namespace hexfem
