// The `hexfem modal` command end to end: output, units, JSON, mode shapes, and every bad input
// a clear error with a non-zero exit.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fem_test_util.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh/structured_box.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

using test::CliRun;

CliRun run(const std::string& command) {
  return test::run_command(command);
}

CliRun hexfem(const std::string& args) {
  return run(std::string(HEXFEM_BINARY) + " " + args);
}

fs::path work(const std::string& name) {
  const fs::path dir = fs::path(HEXFEM_WORK_DIR) / "fem_cli";
  fs::create_directories(dir);
  return dir / name;
}

// 100 x 10 x 10 mm beam, hex 20x2x2, written once.
std::string beam_msh() {
  static const fs::path p = [] {
    const fs::path path = work("beam_mm.msh");
    write_mesh(make_box_mesh({100, 10, 10}, 20, 2, 2, CellKind::Hex8), path);
    return path;
  }();
  return p.string();
}

TEST(ModalCli, TableStatesUnitsAndMaterial) {
  const CliRun r = hexfem("modal " + beam_msh() + " --fix face:1 --units mm --modes 4");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("lengths in mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("E = 2.1e+11 Pa"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--fix face:1: 9 nodes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mode  frequency [Hz]"), std::string::npos) << r.out;
}

TEST(ModalCli, JsonAndUnitScaling) {
  const CliRun mm =
      hexfem("modal " + beam_msh() + " --fix \"x<0.001\" --units mm --modes 2 --json");
  ASSERT_EQ(mm.code, 0) << mm.out;
  const auto j = nlohmann::json::parse(mm.out);
  const double f_mm = j["modes"][0]["frequency_hz"];
  EXPECT_EQ(j["order"], 1);  // a mesh file is solved at its own order unless --order is given
  EXPECT_NEAR(j["mass_kg"].get<double>(), 7850 * 1e-5, 1e-12);
  // The same file read as metres: a 100 m beam, frequencies 1000x lower, and a warning.
  const CliRun si = hexfem("modal " + beam_msh() + " --fix \"x<0.001\" --modes 2 --json");
  ASSERT_EQ(si.code, 0) << si.out;
  const auto k = nlohmann::json::parse(si.out);
  EXPECT_NEAR(k["modes"][0]["frequency_hz"].get<double>() * 1000, f_mm, 1e-6 * f_mm);
  ASSERT_EQ(k["warnings"].size(), 1u);
  EXPECT_NE(k["warnings"][0].get<std::string>().find("--units mm"), std::string::npos);
  // Material override: f ~ sqrt(E/rho).
  const CliRun soft =
      hexfem("modal " + beam_msh() + " --fix \"x<0.001\" --units mm --modes 2 --json --E 52.5e9");
  ASSERT_EQ(soft.code, 0) << soft.out;
  EXPECT_NEAR(nlohmann::json::parse(soft.out)["modes"][0]["frequency_hz"].get<double>() * 2, f_mm,
              1e-6 * f_mm);
}

TEST(ModalCli, ModeShapesVtu) {
  const fs::path out = work("modes.vtu");
  fs::remove(out);
  const CliRun r = hexfem("modal " + beam_msh() +
                          " --fix face:1 --units mm --modes 3 --modes-out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Name=\"mode_3\""), std::string::npos);
  EXPECT_NE(text.find("NumberOfPoints=\"189\""), std::string::npos);
  EXPECT_NE(text.find("</VTKFile>"), std::string::npos);
  // An independent reader sees three unit-normalised vector fields on the 189 points and the
  // three frequencies.
  const CliRun py =
      run("/usr/bin/python3 -c \"import meshio, numpy as np; m = meshio.read('" + out.string() +
          "'); print(*[m.point_data['mode_%d' % k].shape for k in (1, 2, 3)], "
          "round(max(np.linalg.norm(m.point_data['mode_1'], axis=1)), 6), "
          "len(m.field_data['frequency_hz']))\"");
  ASSERT_EQ(py.code, 0) << py.out;
  EXPECT_EQ(py.out, "(189, 3) (189, 3) (189, 3) 1.0 3\n");
}

// Exit 1 or 2 (not a signal) and exactly one line: "hexfem: error: ..." containing `message`.
void expect_error(const std::string& args, const std::string& message) {
  const CliRun r = hexfem("modal " + args);
  EXPECT_TRUE(r.code == 1 || r.code == 2) << args << "\n" << r.out;
  EXPECT_EQ(r.out.rfind("hexfem: error: ", 0), 0u) << args << "\n" << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
  EXPECT_NE(r.out.find(message), std::string::npos) << args << "\n" << r.out;
}

TEST(ModalCli, BadInputIsAClearError) {
  const std::string b = beam_msh() + " --units mm ";
  expect_error(b + "--fix face:1 --E -1", "Young's modulus E must be positive");
  expect_error(b + "--fix face:1 --rho -7850", "density rho must be positive");
  expect_error(b + "--fix face:1 --rho 0", "density rho must be positive");
  expect_error(b + "--fix face:1 --nu 0.5", "Poisson's ratio nu must be in (-1, 0.5)");
  expect_error(b + "--fix face:1 --nu 0.7", "Poisson's ratio nu must be in (-1, 0.5)");
  expect_error(b + "--fix face:9", "no boundary face has this CAD-face id");
  expect_error(b + "--fix face:1.0", "is not a CAD-face id");  // the CLI's rule (issue 17)
  expect_error(b + "--fix \"x<-5\"", "selects no node");
  expect_error(b, "no boundary condition");
  expect_error(b + "--fix face:1 --modes 100000", "free DOFs");
  expect_error(b + "--fix face:1 --modes 0", "at least 1");
  expect_error(b + "--fix face:1 --material unobtainium", "unknown material");
  expect_error(beam_msh() + " --fix face:1 --units inch", "--units must be SI");
  expect_error(work("missing.msh").string() + " --fix face:1", "missing.msh");
  // every DOF fixed
  expect_error(b + "--fix \"x>-1\"", "every DOF is fixed");
}

// `hexfem mesh` writes millimetres and says so in the file: read back, no --units is needed,
// and a --units that contradicts the file is refused (frequencies 1000x off otherwise).
TEST(ModalCli, AMeshThatRecordsItsUnitIsSolvedInIt) {
  MixedMesh m = make_box_mesh({100, 10, 10}, 20, 2, 2, CellKind::Hex8);
  m.length_unit = "mm";
  const fs::path p = work("beam_records_mm.msh");
  write_mesh(m, p);
  const CliRun told = hexfem("modal " + beam_msh() + " --fix face:1 --units mm --modes 2 --json");
  const CliRun recorded = hexfem("modal " + p.string() + " --fix face:1 --modes 2 --json");
  ASSERT_EQ(told.code, 0) << told.out;
  ASSERT_EQ(recorded.code, 0) << recorded.out;
  const auto t = nlohmann::json::parse(told.out), r = nlohmann::json::parse(recorded.out);
  EXPECT_EQ(r["modes"][0]["frequency_hz"], t["modes"][0]["frequency_hz"]);
  EXPECT_EQ(r["units"]["length"], "mm");
  EXPECT_EQ(r["units"]["length_from"], "recorded in the mesh file");
  EXPECT_EQ(t["units"]["length_from"], "--units");
  EXPECT_TRUE(r["warnings"].empty()) << recorded.out;
  const CliRun agrees = hexfem("modal " + p.string() + " --fix face:1 --units mm --modes 2");
  EXPECT_EQ(agrees.code, 0) << agrees.out;
  EXPECT_NE(agrees.out.find("lengths in mm (recorded in the mesh file;"), std::string::npos)
      << agrees.out;
  expect_error(p.string() + " --fix face:1 --units SI",
               "records its coordinates in mm; --units SI contradicts it");
  // stats names the unit, and says null for a file that records none (always the key).
  const CliRun with = hexfem("stats " + p.string() + " --json");
  const CliRun without = hexfem("stats " + beam_msh() + " --json");
  ASSERT_EQ(with.code, 0) << with.out;
  ASSERT_EQ(without.code, 0) << without.out;
  EXPECT_EQ(nlohmann::json::parse(with.out)["length_unit"], "mm");
  EXPECT_TRUE(nlohmann::json::parse(without.out).at("length_unit").is_null());
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Issue 14 items 4, 6, 7 and 9: refused before any work, in one line, the input intact and no
// file written.
TEST(ModalCli, BadOutputsAndNumbersAreRefusedUpFront) {
  const fs::path dir = work("up_front");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path input = dir / "m.msh";
  fs::copy_file(beam_msh(), input);
  const std::string before = slurp(input);
  const std::string b = input.string() + " --units mm --fix face:1 ";
  expect_error(b + "--modes-out " + input.string(), "is an input of this command");
  expect_error(b + "--modes-out " + (dir / "x.msh").string(), "must end in .vtu");
  expect_error(b + "--modes-out " + (dir / "nope" / "x.vtu").string(), "does not exist");
  expect_error(b + "--modes-out " + dir.string() + "/", "must end in .vtu");
  expect_error(b + "--mesh-out " + (dir / "x.msh").string(), "--mesh-out is for CAD input");
  expect_error(b + "--size-at face:1=0.5", "--size-at is for CAD input");
  expect_error(b + "--curvature 12", "--curvature is for CAD input");
  expect_error(b + "--relax-points 30", "--relax-points is for CAD input");
  expect_error(b + "--align-opposite 2", "--align-opposite is for CAD input");
  expect_error(b + "--no-pyramids", "--no-pyramids is for CAD input");
  expect_error(b + "--no-edge-spacing-size", "--no-edge-spacing-size is for CAD input");
  expect_error(b + "--glue", "--glue is for CAD input");
  expect_error(b + "--E nan", "--E must be a finite number");
  expect_error(b + "--nu nan", "--nu must be a finite number");
  expect_error(b + "--rho inf", "--rho must be a finite number");
  expect_error(b + "--modes 10000", "(at most 539 modes)");
  expect_error(dir.string() + " --fix face:1", "is a directory");
  EXPECT_EQ(slurp(input), before);
  EXPECT_EQ(listing(dir), std::vector<std::string>{"m.msh"});
  // The extension is compared in any case.
  const CliRun r = hexfem("modal " + b + "--modes 2 --modes-out " + (dir / "SHAPES.VTU").string());
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "SHAPES.VTU"));
}

TEST(ModalCli, InvertedElementIsAnError) {
  MixedMesh m = make_box_mesh({1, 1, 1}, 2, 2, 2, CellKind::Hex8);
  // Mirror cell 3: swap its bottom and top faces.
  for (int i = 0; i < 4; ++i) std::swap(m.cell_nodes[8 * 3 + i], m.cell_nodes[8 * 3 + 4 + i]);
  const fs::path p = work("inverted.msh");
  write_mesh(m, p);
  expect_error(p.string() + " --fix face:1", "inverted");
}

TEST(ModalCli, FlatElementIsAnError) {
  // A unit hex with a tet on its top face whose apex is 1e-10 above that face: nothing is
  // inverted, but the tet is flat (scaled Jacobian ~1e-10) and must be refused.
  MixedMesh m = make_box_mesh({1, 1, 1}, 1, 1, 1, CellKind::Hex8);
  std::vector<std::int32_t> tri;
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    if (m.nodes[i][2] == 1.0 && !(m.nodes[i][0] == 1.0 && m.nodes[i][1] == 1.0))
      tri.push_back(static_cast<std::int32_t>(i));
  ASSERT_EQ(tri.size(), 3u);
  m.nodes.push_back({0.3, 0.3, 1 + 1e-10});
  const auto apex = static_cast<std::int32_t>(m.nodes.size() - 1);
  m.add_cell(CellKind::Tet4, {tri[0], tri[1], tri[2], apex});
  if (cell_is_inverted(m, 1)) std::swap(m.cell_nodes[8 + 0], m.cell_nodes[8 + 1]);
  ASSERT_FALSE(cell_is_inverted(m, 1));
  ASSERT_TRUE(cell_is_degenerate(m, 1));
  const fs::path p = work("flat.msh");
  write_mesh(m, p);
  expect_error(p.string() + " --free --units mm", "degenerate");
}

TEST(ModalCli, FreeFreeNeedsNoFix) {
  const CliRun r = hexfem("modal " + beam_msh() + " --free --units mm --modes 7 --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  const double f7 = j["modes"][6]["frequency_hz"];
  for (int i = 0; i < 6; ++i)
    EXPECT_LT(std::abs(j["modes"][i]["frequency_hz"].get<double>()), 1e-6 * f7);
}

// `modal` meshes a CAD part without the lattice relaxation that `mesh` does by default (its extra
// hexes double the sphere's order-2 error at equal DOF): the default is the mesh of
// `--relax-points 0`, and asking for the relaxation gives another.
TEST(ModalCli, CadPartIsMeshedWithoutTheRelaxationUnlessAsked) {
  const std::string base =
      "modal " + std::string(HEXFEM_TEST_DATA) + "/sphere.stp --h 5 --free --modes 7 --json";
  auto dofs = [&](const std::string& extra) {
    const CliRun r = hexfem(base + extra);
    EXPECT_EQ(r.code, 0) << r.out;
    return r.code == 0 ? nlohmann::json::parse(r.out)["free_dofs"].get<long>() : -1L;
  };
  const long by_default = dofs("");
  EXPECT_GT(by_default, 0);
  EXPECT_EQ(by_default, dofs(" --relax-points 0"));
  EXPECT_NE(by_default, dofs(" --relax-points 30"));
}

}  // namespace
}  // namespace hexfem
