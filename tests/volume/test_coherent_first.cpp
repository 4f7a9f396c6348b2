// Coherent walls first (VolumePointsOptions::coherent_first, on for `hexfem mesh`): the fronts of
// box-like planar walls fill the part first, the fronts of curved faces and of the walls around
// holes the layers left. On a plate with holes that makes more of the volume hexes, read back
// from the written file by `hexfem stats`; on a part with no such walls (a sphere) the mesh is the
// one every front at once gives, byte for byte.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tests/cad/cad_test_util.hpp"

namespace hexfem {
namespace {

// The written mesh's H_vol and inverted count, as `hexfem stats --json` reads them back.
nlohmann::json stats_of(const std::string& msh) {
  int rc = 0;
  const auto j = cadtest::run_cli_json("stats " + msh + " --json", &rc);
  EXPECT_EQ(rc, 0) << j;
  return j;
}

// freecad_hole_puzzle_counterbore at its diagonal / 60: a block with counterbored holes. Session
// 31: H_vol 84.72 % with every front at once, 88.57 % with the walls' fronts first.
TEST(CoherentFirst, APlateWithHolesGetsMoreOfItsVolumeInHexes) {
  const std::string model = cadtest::data("freecad_hole_puzzle_counterbore.brep");
  const std::string lead = cadtest::work("puzzle_lead.msh").string();
  const std::string all = cadtest::work("puzzle_all.msh").string();
  int rc = 0;
  cadtest::run_cli_json("mesh " + model + " --h 0.43271 --json -o " + lead, &rc);
  ASSERT_EQ(rc, 0);
  cadtest::run_cli_json("mesh " + model + " --h 0.43271 --no-coherent-first --json -o " + all, &rc);
  ASSERT_EQ(rc, 0);
  const auto a = stats_of(lead), b = stats_of(all);
  EXPECT_EQ(a["inverted"].get<int>(), 0);
  EXPECT_EQ(b["inverted"].get<int>(), 0);
  EXPECT_GT(a["H_vol"].get<double>(), b["H_vol"].get<double>() + 2.0)
      << "H_vol with the walls first " << a["H_vol"] << ", all at once " << b["H_vol"];
}

// A sphere's frames turn everywhere: no node leads, so the FIFO is the paper's.
TEST(CoherentFirst, ASphereHasNoLeadingWallsAndKeepsItsMesh) {
  const std::string model = cadtest::data("sphere.stp");
  const std::string lead = cadtest::work("sphere_lead.msh").string();
  const std::string all = cadtest::work("sphere_all.msh").string();
  int rc = 0;
  cadtest::run_cli_json("mesh " + model + " --h 1.039 --json -o " + lead, &rc);
  ASSERT_EQ(rc, 0);
  cadtest::run_cli_json("mesh " + model + " --h 1.039 --no-coherent-first --json -o " + all, &rc);
  ASSERT_EQ(rc, 0);
  const std::string x = cadtest::file_bytes(lead), y = cadtest::file_bytes(all);
  ASSERT_FALSE(x.empty());
  EXPECT_TRUE(x == y);
}

}  // namespace
}  // namespace hexfem
