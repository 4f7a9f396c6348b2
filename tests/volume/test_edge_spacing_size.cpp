// Sizes from the edges' spacing (SurfaceOptions::sizes_from_edge_spacing, the default): a unit
// cube meshed at a size that does not divide its side is a structured grid of n^3 hexes (n the
// segments its edges got), as at a size that does; without it (--no-edge-spacing-size), the faces
// and the volume packed at h meet the edges' spacing off step (h = 0.4: no hex at all).
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/cad/cad_test_util.hpp"

namespace hexfem {
namespace {

nlohmann::json mesh_cube(double h, const std::string& switches) {
  std::string out;
  EXPECT_EQ(cadtest::run_cli("mesh " + cadtest::data("box.stp") + " --h " + std::to_string(h) +
                                 " --json -o " + HEXFEM_WORK_DIR + "/cube_spacing.msh " + switches,
                             &out),
            0)
      << out;
  const auto brace = out.find('{');
  return brace == std::string::npos ? nlohmann::json{} : nlohmann::json::parse(out.substr(brace));
}

TEST(EdgeSpacingSize, AUnitCubeAtAnyHIsAStructuredGrid) {
  for (double h : {0.4, 0.38, 0.28, 0.22}) {
    const nlohmann::json j = mesh_cube(h, "");
    ASSERT_TRUE(j.contains("vertices")) << h;
    const int n = static_cast<int>(std::lround(std::cbrt(j["vertices"].get<double>()))) - 1;
    EXPECT_EQ(j["vertices"].get<int>(), (n + 1) * (n + 1) * (n + 1)) << "h = " << h;
    EXPECT_EQ(j["cells"]["hex8"].get<int>(), n * n * n) << "h = " << h;
    EXPECT_EQ(j["num_cells"].get<int>(), n * n * n) << "h = " << h;
    EXPECT_NEAR(1.0 / n, h, 0.5 * h) << "h = " << h;
  }
  // Without it at h = 0.4 (3 segments of 1/3 per edge, faces packed at 0.4).
  EXPECT_LT(mesh_cube(0.4, "--no-edge-spacing-size")["h_vol_percent"].get<double>(), 50);
}

}  // namespace
}  // namespace hexfem
