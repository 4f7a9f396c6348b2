// The lattice relaxation of the interior points (VolumePointsOptions::relax_iterations,
// --relax-points): a lattice is left as it is; points that fall off the surface's lattice where
// two fronts meet go back onto it; hexfem mesh with it makes a valid mesh where the first tet
// TetGen gave was flat on a curved face (Torus_1), the same for 1 and 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesher/frame_field_3d.hpp"
#include "mesher/solid_locator.hpp"
#include "mesher/volume_points.hpp"
#include "tests/cad/cad_test_util.hpp"
#include "tests/support/synthetic_surfaces.hpp"

namespace hexfem {
namespace {

VolumePoints points_of(const SurfaceMesh& s, int sweeps) {
  const FrameField3D field(s);
  const SolidLocator loc(s);
  VolumePointsOptions o;
  o.relax_iterations = sweeps;
  return insert_volume_points(s, field, loc, o);
}

TEST(RelaxPoints, ALatticeStaysALattice) {
  const SurfaceMesh s = synthetic::box_surface({2, 1.5, 1}, {8, 6, 4});
  const VolumePoints base = points_of(s, 0), relaxed = points_of(s, 30);
  ASSERT_EQ(relaxed.points.size(), base.points.size());
  for (std::size_t i = 0; i < base.points.size(); ++i)
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(relaxed.points[i][a], base.points[i][a], 1e-12);
}

// A box 2.2 long with 8 surface steps along x (0.275) and a size of 0.25 everywhere: the front
// from x = 0 steps 0.25 inwards while the fronts from the side faces carry the surface's 0.275,
// so where they meet points fall off the surface's lattice (layers at x = 0.5 and 0.55, 1.65
// and 1.7). Relaxed, every interior point is on that lattice again.
TEST(RelaxPoints, PointsWhereFrontsMeetReturnToTheSurfaceLattice) {
  SurfaceMesh s = synthetic::box_surface({2.2, 1.5, 1}, {8, 6, 4});
  for (double& h : s.size) h = 0.25;
  const Vec3 step{0.275, 0.25, 0.25};
  auto off_lattice = [&](const VolumePoints& vp) {
    std::size_t n = 0;
    for (const Vec3& p : vp.points) {
      double worst = 0;
      for (int a = 0; a < 3; ++a)
        worst = std::max(worst, std::abs(p[a] / step[a] - std::round(p[a] / step[a])));
      n += worst > 0.05;
    }
    return n;
  };
  const VolumePoints base = points_of(s, 0), relaxed = points_of(s, 30);
  ASSERT_EQ(relaxed.points.size(), base.points.size());
  EXPECT_GT(off_lattice(base), base.points.size() / 10);
  EXPECT_EQ(off_lattice(relaxed), 0u);
  std::printf("interior points off the surface lattice: %zu of %zu before, %zu after\n",
              off_lattice(base), base.points.size(), off_lattice(relaxed));
}

// Torus_1 at h = diagonal / 30, relaxed: TetGen's first tet was flat on the torus face, its
// centroid outside the chords, and the whole solid used to be dropped (invalid mesh, 0 cells).
// Now a valid mesh, byte-identical with 1 and 2 threads.
TEST(RelaxPoints, TorusMeshesTheSameForOneAndTwoThreads) {
  const std::string work = HEXFEM_WORK_DIR;
  std::string files[2];
  for (int threads = 1; threads <= 2; ++threads) {
    files[threads - 1] = work + "/torus_relax_" + std::to_string(threads) + ".msh";
    const std::string cmd = "OMP_NUM_THREADS=" + std::to_string(threads) + " " +
                            std::string(HEXFEM_BINARY) + " mesh " + HEXFEM_TEST_DATA +
                            "/Torus_1.brep --h 38.2971 --relax-points 10 --json -o " +
                            files[threads - 1] + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    std::string out;
    std::array<char, 4096> buf;
    while (p && fgets(buf.data(), buf.size(), p)) out += buf.data();
    ASSERT_EQ(p ? pclose(p) : -1, 0) << out;
    const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
    EXPECT_EQ(j["inverted"], 0);
    EXPECT_GT(j["h_vol_percent"].get<double>(), 40);
  }
  EXPECT_EQ(cadtest::file_bytes(files[0]), cadtest::file_bytes(files[1]));
}

}  // namespace
}  // namespace hexfem
