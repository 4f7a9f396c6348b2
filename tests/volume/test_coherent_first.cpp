// Coherent walls first (VolumePointsOptions::coherent_first, on for `hexfem mesh`): the fronts of
// box-like planar walls fill the part first, the fronts of curved faces and of the walls around
// holes the layers left. On a plate with holes that makes more of the volume hexes, read back
// from the written file by `hexfem stats`; on a part with no such walls (a sphere) the mesh is the
// one every front at once gives, byte for byte.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <utility>

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

// Meshes `model` at h twice, with the walls first (the default) into work/<name>_lead.msh and
// every front at once into work/<name>_all.msh; returns the two paths.
std::pair<std::string, std::string> mesh_both_ways(const std::string& model, const std::string& h,
                                                   const std::string& name) {
  const std::string lead = cadtest::work(name + "_lead.msh").string();
  const std::string all = cadtest::work(name + "_all.msh").string();
  const std::string args = "mesh " + cadtest::data(model) + " --h " + h + " --json -o ";
  int rc = 0;
  cadtest::run_cli_json(args + lead, &rc);
  EXPECT_EQ(rc, 0);
  cadtest::run_cli_json(args + all + " --no-coherent-first", &rc);
  EXPECT_EQ(rc, 0);
  return {lead, all};
}

// freecad_hole_puzzle_counterbore at its diagonal / 60: a block with counterbored holes. Session
// 31: H_vol 84.72 % with every front at once, 88.57 % with the walls' fronts first.
TEST(CoherentFirst, APlateWithHolesGetsMoreOfItsVolumeInHexes) {
  const auto [lead, all] =
      mesh_both_ways("freecad_hole_puzzle_counterbore.brep", "0.43271", "puzzle");
  const auto a = stats_of(lead), b = stats_of(all);
  EXPECT_EQ(a["inverted"].get<int>(), 0);
  EXPECT_EQ(b["inverted"].get<int>(), 0);
  EXPECT_GT(a["H_vol"].get<double>(), b["H_vol"].get<double>() + 2.0)
      << "H_vol with the walls first " << a["H_vol"] << ", all at once " << b["H_vol"];
}

// A sphere's frames turn everywhere: no node leads, so the FIFO is the paper's.
TEST(CoherentFirst, ASphereHasNoLeadingWallsAndKeepsItsMesh) {
  const auto [lead, all] = mesh_both_ways("sphere.stp", "1.039", "sphere");
  const std::string x = cadtest::file_bytes(lead), y = cadtest::file_bytes(all);
  ASSERT_FALSE(x.empty());
  EXPECT_TRUE(x == y);
}

}  // namespace
}  // namespace hexfem
