// Glued assemblies (--glue): the CAX-IF AS1 assembly (a plate, brackets, a rod, bolts and nuts:
// 18 solids that touch) is refused as it is, since its solids' faces cross. Glued by OCCT's
// General Fuse, touching solids share faces, and the mesh is one bonded body: a free-free modal
// analysis finds exactly six rigid-body modes (18 loose bodies would have 108), the volume is the
// sum of the 18 solids' own volumes, and the bytes do not depend on the thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/cad/cad_test_util.hpp"

namespace hexfem {
namespace {

TEST(Glue, TouchingSolidsOfAnAssemblyMeshAsOneBondedBody) {
  const std::string work = HEXFEM_WORK_DIR;
  const std::string part = cadtest::data("as1-oc-214.stp");
  int status = 0;
  // The solids' own volumes, summed, before any gluing (OCCT's mass properties).
  const nlohmann::json info = cadtest::run_cli_json("info " + part + " --json", &status);
  ASSERT_EQ(status, 0);
  ASSERT_EQ(info["solids"].size(), 18u);
  double solids_volume = 0;
  for (const auto& s : info["solids"]) solids_volume += s["volume"].get<double>();

  std::string refused;
  EXPECT_NE(cadtest::run_cli("mesh " + part + " --h 8 -o " + work + "/as1_plain.msh", &refused), 0);
  EXPECT_NE(refused.find("touch or overlap"), std::string::npos) << refused;
  EXPECT_NE(refused.find("--glue"), std::string::npos) << refused;

  const nlohmann::json two =
      cadtest::run_cli_json("mesh " + part + " --h 8 --glue --json -o " + work + "/as1_glued_2.msh",
                            &status, "OMP_NUM_THREADS=2");
  ASSERT_EQ(status, 0) << two.dump();
  const nlohmann::json one =
      cadtest::run_cli_json("mesh " + part + " --h 8 --glue --json -o " + work + "/as1_glued_1.msh",
                            &status, "OMP_NUM_THREADS=1");
  ASSERT_EQ(status, 0) << one.dump();
  EXPECT_EQ(two["inverted"], 0);
  // Up to the chords of the bolts' and holes' curved faces (measured: 2.0e-4).
  EXPECT_NEAR(two["mesh_volume"].get<double>(), solids_volume, 2e-3 * solids_volume);
  EXPECT_EQ(cadtest::file_bytes(work + "/as1_glued_1.msh"),
            cadtest::file_bytes(work + "/as1_glued_2.msh"));

  // Each solid's volume against its own CAD volume, from `info --glue` (OCCT's mass properties
  // of the glued solids); the file read back by `stats` gives the same volumes per solid.
  const nlohmann::json glued = cadtest::run_cli_json("info " + part + " --glue --json", &status);
  ASSERT_EQ(status, 0);
  ASSERT_EQ(two["solids"].size(), glued["solids"].size());
  const nlohmann::json read =
      cadtest::run_cli_json("stats " + work + "/as1_glued_2.msh --json", &status);
  ASSERT_EQ(status, 0);
  ASSERT_EQ(read["volume_per_solid"].size(), 18u);
  double sum = 0;
  std::string off;  // the solids more than 2 % off, as the warning must list them
  for (std::size_t i = 0; i < 18; ++i) {
    const nlohmann::json& s = two["solids"][i];
    EXPECT_EQ(s["solid"], glued["solids"][i]["id"]);
    const double cad = glued["solids"][i]["volume"].get<double>();
    const double mesh = s["mesh_volume"].get<double>();
    EXPECT_NEAR(s["cad_volume"].get<double>(), cad, 1e-9 * cad);
    EXPECT_NEAR(s["volume_error"].get<double>(), (mesh - cad) / cad, 1e-12);
    EXPECT_NEAR(mesh, cad, 0.05 * cad);  // straight chords of the bolts (measured: -2.6 % worst)
    EXPECT_EQ(read["volume_per_solid"][i]["solid"], s["solid"]);
    EXPECT_NEAR(read["volume_per_solid"][i]["volume"].get<double>(), mesh, 1e-9 * mesh);
    sum += mesh;
    if (std::abs(mesh - cad) > 0.02 * cad)
      off += (off.empty() ? "" : ", ") + std::to_string(s["solid"].get<int>());
  }
  EXPECT_NEAR(sum, two["mesh_volume"].get<double>(), 1e-9 * sum);
  ASSERT_FALSE(off.empty());  // measured: 7 bolts and nuts at h = 8
  bool warned = false;
  for (const auto& w : two["warnings"])
    warned = warned || w.get<std::string>().find("solids " + off + " have mesh volumes") == 0;
  EXPECT_TRUE(warned) << off << " " << two["warnings"].dump();

  const nlohmann::json modal = cadtest::run_cli_json(
      "modal " + part + " --h 8 --glue --order 1 --free --modes 12 --json", &status);
  ASSERT_EQ(status, 0) << modal.dump();
  int rigid = 0;
  for (const auto& m : modal["modes"]) rigid += std::abs(m["frequency_hz"].get<double>()) < 1.0;
  EXPECT_EQ(rigid, 6);
  EXPECT_GT(modal["modes"][6]["frequency_hz"].get<double>(), 1000.0);  // measured 1871.8 Hz
}

// At h = 3 the fuse leaves two surface nodes 1.6 microns apart where an interface face meets an
// outer face in one plane (z = 30, solids 6 and 10): a needle triangle on the outer face, and a
// flat tet on it and on the interface. Every tet on the needle is a sliver, so the 3-2 flip that
// removes the flat tet may make one below flat_tet_quality; refusing that left the needle
// uncovered and the mesh was refused for 3 open boundary edges.
TEST(Glue, AFlatTetOnANeedleAtAnInterfaceIsFlippedAway) {
  const std::string work = HEXFEM_WORK_DIR;
  const std::string part = cadtest::data("as1-oc-214.stp");
  int status = 0;
  const nlohmann::json mesh = cadtest::run_cli_json(
      "mesh " + part + " --h 3 --glue --json -o " + work + "/as1_glued_h3.msh", &status);
  ASSERT_EQ(status, 0) << mesh.dump();
  EXPECT_EQ(mesh["inverted"], 0);
  // measured -3.4e-4 (the chords of the bolts and holes)
  EXPECT_LT(std::abs(mesh["volume_error"].get<double>()), 2e-3);
}

// At order 2 the solids' faces are curved onto the CAD geometry: each solid's volume comes within
// a fraction of its own CAD volume, so no solid is warned of (the bolts were 2.6 % off straight).
TEST(Glue, EachSolidOfAnAssemblyKeepsItsVolumeAtOrderTwo) {
  const std::string work = HEXFEM_WORK_DIR;
  const std::string part = cadtest::data("as1-oc-214.stp");
  int status = 0;
  const nlohmann::json glued = cadtest::run_cli_json("info " + part + " --glue --json", &status);
  ASSERT_EQ(status, 0);
  const nlohmann::json mesh = cadtest::run_cli_json(
      "mesh " + part + " --h 8 --glue --order 2 --json -o " + work + "/as1_order2.msh", &status);
  ASSERT_EQ(status, 0) << mesh.dump();
  ASSERT_EQ(mesh["solids"].size(), 18u);
  for (std::size_t i = 0; i < 18; ++i) {
    const double cad = glued["solids"][i]["volume"].get<double>();
    EXPECT_NEAR(mesh["solids"][i]["mesh_volume"].get<double>(), cad, 2e-3 * cad)
        << "solid " << mesh["solids"][i]["solid"];  // measured: 3.2e-4 worst
  }
  for (const auto& w : mesh["warnings"])
    EXPECT_EQ(w.get<std::string>().find("have mesh volumes"), std::string::npos) << w;
  const nlohmann::json read =
      cadtest::run_cli_json("stats " + work + "/as1_order2.msh --json", &status);
  ASSERT_EQ(status, 0);
  for (std::size_t i = 0; i < 18; ++i) {
    const double v = mesh["solids"][i]["mesh_volume"].get<double>();
    EXPECT_NEAR(read["volume_per_solid"][i]["volume"].get<double>(), v, 1e-9 * v);
  }
}

// A face between two glued solids is outward for the lower id only: the surface check turned it
// over for the other solid only since session 39. Before, `mesh --glue --dim 2` refused AS1 ("64
// misoriented edges" in solid 3), and the volume path took the false defect for a reason to mesh
// again at a curvature bound (its mesh happened to be better; now the solids' own volumes ask for
// it, with the same bytes at h = 8).
TEST(Glue, TheSurfaceOfEachGluedSolidIsClosedAndOutward) {
  const std::string work = HEXFEM_WORK_DIR;
  const std::string part = cadtest::data("as1-oc-214.stp");
  int status = 0;
  const nlohmann::json s = cadtest::run_cli_json(
      "mesh " + part + " --h 8 --glue --dim 2 --json -o " + work + "/as1_surface.msh", &status);
  ASSERT_EQ(status, 0) << s.dump();
  ASSERT_EQ(s["solids"].size(), 18u);
  double enclosed = 0;
  for (const auto& solid : s["solids"]) {
    EXPECT_TRUE(solid["closed"].get<bool>()) << solid;
    EXPECT_TRUE(solid["oriented"].get<bool>()) << solid;
    enclosed += solid["volume"].get<double>();
  }
  // The interfaces' chords move volume between solids, not out of the part (measured -0.60 %).
  EXPECT_NEAR(enclosed, s["cad_volume"].get<double>(), 0.01 * s["cad_volume"].get<double>());
}

}  // namespace
}  // namespace hexfem
