// A solid whose two lumps touch along an edge: the housing blank gehause_rohteil (FreeCAD's
// example part), whose edge 51 bounds four face sides (faces 18, 20, 23 and 44). It was refused
// as "not manifold"; Gmsh meshes it. Its surface mesh is closed and oriented though not manifold
// along that edge (each lump's sheet uses it once each way), so it must pass the surface checks
// at once (no curvature retry), give a valid volume mesh of the CAD volume whose bytes do not
// depend on the thread count, and a free-free spectrum with exactly six rigid-body modes and the
// elastic frequencies of an independent chain (Gmsh tet10 + CalculiX C3D10, extrapolated:
// validation/reference/gehause_free.json).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/cad/cad_test_util.hpp"

namespace hexfem {
namespace {

TEST(TouchingLumps, ASolidWhoseLumpsTouchAlongAnEdgeMeshesAndVibratesAsOneBody) {
  const std::string work = HEXFEM_WORK_DIR;
  const std::string part = cadtest::data("gehause_rohteil.stp");
  int status = 0;

  // `info` names the edge before any meshing.
  const nlohmann::json info = cadtest::run_cli_json("info " + part + " --json", &status);
  ASSERT_EQ(status, 0) << info.dump();
  EXPECT_NE(info["warnings"].dump().find("touch along CAD edge 51"), std::string::npos)
      << info["warnings"].dump();

  const nlohmann::json surface = cadtest::run_cli_json(
      "mesh " + part + " --h 1.396 --dim 2 --json -o " + work + "/geh_surface.msh", &status);
  ASSERT_EQ(status, 0) << surface.dump();
  ASSERT_EQ(surface["solids"].size(), 1u);
  EXPECT_TRUE(surface["solids"][0]["closed"].get<bool>());
  EXPECT_TRUE(surface["solids"][0]["oriented"].get<bool>());
  EXPECT_FALSE(surface["solids"][0]["self_intersects"].get<bool>());
  EXPECT_GT(surface["solids"][0]["touching_edges"].get<int>(), 0);  // the segments of edge 51
  EXPECT_EQ(surface["curvature_used"], 0);                          // accepted at once

  const nlohmann::json two = cadtest::run_cli_json(
      "mesh " + part + " --h 1.396 --json -o " + work + "/geh_2.msh", &status, "OMP_NUM_THREADS=2");
  ASSERT_EQ(status, 0) << two.dump();
  const nlohmann::json one = cadtest::run_cli_json(
      "mesh " + part + " --h 1.396 --json -o " + work + "/geh_1.msh", &status, "OMP_NUM_THREADS=1");
  ASSERT_EQ(status, 0) << one.dump();
  EXPECT_EQ(two["inverted"], 0);
  // Up to the chords of the holes and rounds at this coarse size (measured +0.45 %).
  EXPECT_NEAR(two["mesh_volume"].get<double>(), two["cad_volume"].get<double>(),
              0.01 * two["cad_volume"].get<double>());
  EXPECT_EQ(cadtest::file_bytes(work + "/geh_1.msh"), cadtest::file_bytes(work + "/geh_2.msh"));
  // The user hears where the lumps touch: the joint is only a line of nodes.
  bool told = false;
  for (const auto& w : two["warnings"])
    told |= w.get<std::string>().find("touch along CAD edge 51") != std::string::npos;
  EXPECT_TRUE(told) << two["warnings"].dump();

  std::ifstream ref_file(std::string(HEXFEM_SOURCE_DIR) +
                         "/validation/reference/gehause_free.json");
  ASSERT_TRUE(ref_file) << "validation/reference/gehause_free.json";
  const nlohmann::json ref = nlohmann::json::parse(ref_file);
  const nlohmann::json modal =
      cadtest::run_cli_json("modal " + part + " --h 1.396 --free --modes 10 --json", &status);
  ASSERT_EQ(status, 0) << modal.dump();
  ASSERT_EQ(modal["modes"].size(), 10u);
  int rigid = 0;
  for (const auto& m : modal["modes"]) rigid += std::abs(m["frequency_hz"].get<double>()) < 1.0;
  EXPECT_EQ(rigid, 6);  // a hinge along the edge, or a loose lump, would add more
  for (int k = 0; k < 4; ++k) {
    const double f = modal["modes"][6 + k]["frequency_hz"].get<double>();
    const double f_ref = ref["reference_hz"][k].get<double>();
    // Order 2 at this size, its re-entrant edges graded by default, is above the reference by
    // +0.66 to +0.97 % (measured; +0.9 to +1.4 % uniform); the reference is good to 0.15-0.23 %.
    EXPECT_GT(f, f_ref * 0.995) << "elastic mode " << k + 1;
    EXPECT_LT(f, f_ref * 1.02) << "elastic mode " << k + 1;
  }
}

}  // namespace
}  // namespace hexfem
