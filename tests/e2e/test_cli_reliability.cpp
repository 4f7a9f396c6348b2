// Issue 14 through the CLI, each case as a user meets it: one "hexfem: error:" line, a non-zero
// exit code, and no file left behind or damaged. The cases not covered next to their own
// commands (test_cli, test_cli_modal, test_cli_surface) are here.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cad/cad_test_util.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;
using cadtest::data;
using cadtest::run_cli;
using cadtest::work;

void expect_error(const std::string& args, const std::string& needle) {
  cadtest::expect_one_line_error(args, needle);
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = work(name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

bool nothing_in(const fs::path& d) {
  return fs::directory_iterator(d) == fs::directory_iterator();
}

// Item 1: OpenCASCADE threw Standard_OutOfRange from a B-spline evaluation inside the parallel
// face loop (exit 134). The whole command now meshes the part.
TEST(Reliability, BSplineSphereFromRhinoMeshesWholeParts) {
  const fs::path dir = fresh_dir("rel_rhino");
  std::string out;
  for (const char* h : {"2", "0.8"}) {
    const fs::path msh = dir / (std::string("s") + h + ".msh");
    EXPECT_EQ(
        run_cli("mesh " + data("sphere_Rhino3D_default.igs") + " --h " + h + " -o " + msh.string(),
                &out),
        0)
        << out;
    EXPECT_TRUE(fs::exists(msh)) << out;
  }
}

// Item 3: a 100 x 100 x 0.01 mm plate at --h 5 grew past 2.4 GB with no answer; the size field
// follows the thickness, so the points are estimated from the sizes the edges got and the run
// is refused before the work, naming the face and the estimate. A vertex size of 1e-9 hung in
// graded_sizes; sizes below 1e-5 of the diagonal are refused by name.
TEST(Reliability, ThinPlateAndTinySizesAreRefusedBeforeTheWork) {
  const fs::path dir = fresh_dir("rel_thin");
  expect_error("mesh " + data("thin_plate.step") + " --h 5 -o " + (dir / "p.msh").string(),
               "set by a thin wall or small feature");
  expect_error("mesh " + data("thin_plate.step") + " --h 5 -o " + (dir / "p.msh").string(),
               "surface points (more than 1e+06)");
  expect_error(
      "mesh " + data("box.stp") + " --h 0.2 --size-at vertex:1=1e-9 -o " + (dir / "b.msh").string(),
      "are not resolved");
  EXPECT_TRUE(nothing_in(dir));
}

// Item 7: output paths and extensions are checked before minutes of meshing, for every
// command that writes.
TEST(Reliability, OutputPathsAreCheckedBeforeTheWork) {
  const fs::path dir = fresh_dir("rel_paths");
  const std::string part = data("box.stp");
  expect_error("mesh " + part + " --h 0.3 -o /nonexistent-hexfem/x.msh", "does not exist");
  expect_error("mesh " + part + " --h 0.3 -o " + (dir / "x.xyz").string(),
               "must end in .msh, .vtu or .inp");
  expect_error("modal " + part + " --h 0.3 --fix face:1 --mesh-out " + (dir / "x.xyz").string(),
               "must end in .msh, .vtu or .inp");
  expect_error("modal " + part + " --h 0.3 --fix face:1 --modes-out " + (dir / "x.msh").string(),
               ".vtu");
  expect_error("converge " + part + " --h 0.3,0.2 --fix face:1 -o /nonexistent-hexfem/c",
               "does not exist");
  // A folder no file can be made in, whatever its permission bits say (to root too): refused
  // before the work, and the other outputs of the run not written either.
  expect_error("mesh " + part + " --h 0.3 -o /proc/x.msh", "is not writable");
  expect_error("modal " + part + " --h 0.3 --fix face:1 --mesh-out " + (dir / "ok.msh").string() +
                   " --modes-out /proc/m.vtu",
               "is not writable");
  EXPECT_TRUE(nothing_in(dir));
  expect_error("mesh " + part + " --h 0.3 -o ''",
               "the value after -o is empty");  // was: no output, exit 0
  // A number read from an empty value was 0 ("--h must be > 0 (got 0.000000)").
  expect_error("mesh " + part + " --h '' -o " + (dir / "x.msh").string(),
               "the value after --h is empty");
  expect_error("modal " + part + " --h 0.3 --fix face:1 --modes ''",
               "the value after --modes is empty");
  expect_error("modal " + part + " --h 0.3 --free --ccx-deck ''",
               "the value after --ccx-deck is empty");
  const fs::path file = fresh_dir("rel_paths_file") / "f";
  std::ofstream(file) << "a file\n";
  expect_error("mesh " + part + " --h 0.3 -o " + (file / "x.msh").string(),
               "is a file, not a folder");
}

// Item 9b: extensions in any case, for every output option.
TEST(Reliability, UpperCaseExtensionsAreAccepted) {
  const fs::path dir = fresh_dir("rel_case");
  std::string out;
  EXPECT_EQ(run_cli("mesh " + data("box.stp") + " --h 0.3 -o " + (dir / "OUT.MSH").string(), &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(dir / "OUT.MSH"));
  EXPECT_EQ(run_cli("convert " + (dir / "OUT.MSH").string() + " " + (dir / "C.INP").string(), &out),
            0)
      << out;
  EXPECT_TRUE(fs::exists(dir / "C.INP"));
}

// Item 9a: a FIFO (or any non-regular file) as the CAD input is refused, not read for ever.
TEST(Reliability, AFifoAsCadInputIsRefused) {
  const fs::path dir = fresh_dir("rel_fifo");
  ASSERT_EQ(::mkfifo((dir / "part.stp").c_str(), 0600), 0);
  expect_error("info " + (dir / "part.stp").string(), "not a regular file");
  expect_error("mesh " + (dir / "part.stp").string() + " --h 1 -o " + (dir / "x.msh").string(),
               "not a regular file");
  fs::remove(dir / "part.stp");
  EXPECT_TRUE(nothing_in(dir));
}

// Item 6: NaN material constants fell back to steel with exit 0.
TEST(Reliability, NanMaterialIsRefused) {
  const std::string run = "modal " + data("box.stp") + " --h 0.3 --fix face:1 ";
  expect_error(run + "--E nan", "--E must be a finite number");
  expect_error(run + "--nu nan", "--nu must be a finite number");
  expect_error(run + "--rho nan", "--rho must be a finite number");
}

// Item 9c: at a size near the part's own, a stage fails in its own terms; the message says that
// the size is the cause.
TEST(Reliability, ASizeLargerThanThePartIsNamedAsTheCause) {
  const fs::path dir = fresh_dir("rel_large");
  expect_error("mesh " + data("tie_rod.step") + " --h 500 -o " + (dir / "x.msh").string(),
               "--h 500 is too large for this part");
  EXPECT_TRUE(nothing_in(dir));
}

// Item 9d: a mesh far off the CAD volume (chords across a whole sphere) is an error unless
// --force, and then it is written with a warning.
TEST(Reliability, AMeshFarOffTheCadVolumeNeedsForce) {
  const fs::path dir = fresh_dir("rel_volume");
  const std::string run =
      "mesh " + data("sphere.stp") + " --h 100 -o " + (dir / "x.msh").string() + " ";
  expect_error(run, "off the CAD volume");
  EXPECT_TRUE(nothing_in(dir));
  std::string out;
  EXPECT_EQ(run_cli(run + "--force", &out), 0) << out;
  EXPECT_TRUE(fs::exists(dir / "x.msh"));
  EXPECT_NE(out.find("off the CAD volume"), std::string::npos) << out;
}

// Item 9e: a malformed --reference leaked nlohmann's "[json.exception.type_error.302]"; it is
// read before the work.
TEST(Reliability, ABadReferenceIsOneLine) {
  const fs::path dir = fresh_dir("rel_reference");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string run = "converge " + data("box.stp") + " --h 0.3 --fix face:1 --reference ";
  expect_error(run + write("a.json", "{\"reference_hz\": [\"x\", 2]}"), "must hold positive");
  expect_error(run + write("b.json", "{\"reference_hz\": 5}"), "has no \"reference_hz\" array");
  expect_error(run + write("c.json", "{\"reference_hz\": [1,"), "is not valid JSON");
  expect_error(run + (dir / "none.json").string(), "cannot read reference");
}

// converge writes its table, Markdown and plot and nothing else: gnuplot takes its data in the
// script and gives the PNG on its stdout (before, <stem>.plot.gp, .plot.dat and .png.tmp were
// files under fixed names, left behind by a signal).
TEST(Reliability, ConvergeWritesItsOutputsAndNothingElse) {
  const fs::path dir = fresh_dir("rel_converge");
  std::ofstream(dir / "ref.json") << "{\"reference_hz\": [2000, 3000, 4000, 5000]}";
  std::string out;
  ASSERT_EQ(
      run_cli("converge " + data("box.stp") + " --h 0.5,0.3 --fix face:1 --modes 4 " +
                  "--reference " + (dir / "ref.json").string() + " -o " + (dir / "c").string(),
              &out),
      0)
      << out;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"c.csv", "c.md", "c.png", "ref.json"}));
  std::ifstream png(dir / "c.png", std::ios::binary);
  std::string magic(4, '\0');
  png.read(magic.data(), 4);
  EXPECT_EQ(magic, "\x89PNG");
}

// Two sizes that give the same node and cell counts need not give the same mesh: the cube at
// h = 4 and 3 (27 cells each, other node positions and other frequencies) was said to be one
// mesh and no order was read from it (interop audit, helper 12). The cylinder at h = 6 and 4.5
// gives one mesh (its curvature bound sets the size; coordinates equal to their last bits), and
// is still said to.
TEST(Reliability, ConvergeSaysTheSameMeshOnlyOfTheSameMesh) {
  const fs::path dir = fresh_dir("rel_converge_same");
  std::string out;
  ASSERT_EQ(run_cli("converge " + data("cube_10x10.igs") + " --h 4,3 --fix face:1 --modes 2 -o " +
                        (dir / "c").string(),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("\n4  "), std::string::npos) << out;
  EXPECT_EQ(out.find("gave the same mesh"), std::string::npos) << out;
  ASSERT_EQ(run_cli("converge " + data("cylinder.stp") + " --h 6,4.5 --fix face:1 --modes 2 -o " +
                        (dir / "y").string(),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("h = 4.5 gave the same mesh as h = 6"), std::string::npos) << out;
}

// The tie rod at its diagonal / 30: the chords cut 22 % off its volume. The volume mesh was
// made again with a curvature bound, while `mesh --dim 2` refused the same part ("too large for
// this part"). Now the surface command retries the same way: the surface of the volume mesh,
// with the same warning.
TEST(Reliability, ASurfaceMeshIsMadeAgainAtACurvatureBoundAsTheVolumeIs) {
  const std::string part = data("tie_rod.step") + " --h 4.264755 ";
  int status = 0;
  const nlohmann::json surface = cadtest::run_cli_json(
      "mesh " + part + "--dim 2 --json -o " + work("tie_rod_surface.msh").string(), &status);
  ASSERT_EQ(status, 0) << surface.dump();
  const nlohmann::json volume = cadtest::run_cli_json(
      "mesh " + part + "--json -o " + work("tie_rod_volume.msh").string(), &status);
  ASSERT_EQ(status, 0) << volume.dump();
  EXPECT_EQ(surface["points"], volume["surface_points"]);
  EXPECT_EQ(surface["curvature_used"], 16);
  ASSERT_EQ(surface["warnings"].size(), 1u) << surface["warnings"];
  EXPECT_NE(surface["warnings"][0].get<std::string>().find("-22.3 % off the CAD volume; meshed "
                                                           "again with a curvature bound of 16"),
            std::string::npos)
      << surface["warnings"];
}

// Item 9k: a .vtu output of a mesh with NC faces has a companion <stem>_nc.vtu; it is checked
// with the main output before the work, so the main file is never written alone.
TEST(Reliability, TheNcCompanionOfAVtuIsCheckedBeforeTheWork) {
  const fs::path dir = fresh_dir("rel_nc_companion");
  fs::create_directories(dir / "x_nc.vtu");
  expect_error("mesh " + data("cylinder.stp") + " --h 3 -o " + (dir / "x.vtu").string(),
               "its NC-face companion");
  EXPECT_FALSE(fs::exists(dir / "x.vtu"));
}

}  // namespace
}  // namespace hexfem
