// `hexfem modal --ccx-deck JOB.inp`: CalculiX run on the deck gives hexfem's frequencies where
// both integrate the same element the same way (C3D8 = --hex8 full, C3D20 = hex20), with a
// material per solid, in mm and in metres; and a bad deck name is a one-line error.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fem_test_util.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/structured_box.hpp"
#include "tests/support/ccx_reference.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

fs::path work_dir(const std::string& name) {
  const fs::path dir = fs::path(HEXFEM_WORK_DIR) / "ccx_deck" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// 100 x 10 x 10 (mm or m) bar of 20 x 2 x 2 hexes: solid 1 for x < 50, solid 2 beyond.
fs::path two_solid_bar(const fs::path& dir) {
  MixedMesh mesh = make_box_mesh({100, 10, 10}, 20, 2, 2, CellKind::Hex8);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c)
    mesh.cell_solid[c] = mesh.nodes[mesh.cell(c)[0]][0] < 49 ? 1 : 2;
  const fs::path path = dir / "bar.msh";
  write_mesh(mesh, path);
  return path;
}

// hexfem's frequencies with --ccx-deck, then ccx on the deck; both lists.
std::pair<std::vector<double>, std::vector<double>> both(const fs::path& dir,
                                                         const std::string& args) {
  const test::CliRun r = test::run_command(std::string(HEXFEM_BINARY) + " modal " + args +
                                           " --json --ccx-deck " + (dir / "job.inp").string());
  EXPECT_EQ(r.code, 0) << r.out;
  std::vector<double> ours;
  const auto j = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  for (const auto& m : j["modes"]) ours.push_back(m["frequency_hz"].get<double>());
  EXPECT_EQ(j["ccx_deck"].size(), 2u);
  EXPECT_TRUE(fs::exists(dir / "job_mesh.inp"));
  const test::CliRun ccx =
      test::run_command("cd " + dir.string() + " && OMP_NUM_THREADS=1 ccx job > ccx.log");
  EXPECT_EQ(ccx.code, 0) << ccx.out;
  std::ifstream dat(dir / "job.dat");
  return {ours, parse_ccx_dat(dat).frequencies};
}

std::string text_of(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expect_equal(const std::vector<double>& ours, const std::vector<double>& ccx, double tol,
                  const char* what) {
  ASSERT_EQ(ours.size(), ccx.size()) << what;
  for (std::size_t i = 0; i < ours.size(); ++i) {
    std::printf("%s mode %zu: hexfem %.7g Hz, ccx on the deck %.7g Hz, rel. diff %.1e\n", what,
                i + 1, ours[i], ccx[i], ours[i] / ccx[i] - 1);
    EXPECT_NEAR(ours[i] / ccx[i] - 1, 0.0, tol) << what << " mode " << i + 1;
  }
}

TEST(CcxDeck, SteelAndAluminiumBarInMillimetresAsHexfemSolvesIt) {
  const fs::path dir = work_dir("mm");
  const auto [ours, ccx] = both(dir, two_solid_bar(dir).string() +
                                         " --units mm --fix face:1 --modes 5 --hex8 full "
                                         "--material solid:2=aluminium");
  expect_equal(ours, ccx, 1e-6, "bar, mm, hex8 = C3D8");
  // The deck says where each material goes and keeps ccx's 20-character fields.
  const std::string deck = text_of(dir / "job.inp");
  EXPECT_NE(deck.find("*SOLID SECTION, ELSET=SOLID_2, MATERIAL=M2\n"), std::string::npos);
  EXPECT_NE(deck.find("*ELASTIC\n70000, 0.33\n*DENSITY\n2.7e-09\n"), std::string::npos) << deck;
}

TEST(CcxDeck, OrderTwoInMetres) {
  // The same file read as metres (a 100 m bar), at order 2 (straight mid-edge nodes): hex20 is
  // ccx's C3D20, the material in Pa and kg/m^3.
  const fs::path dir = work_dir("si_order2");
  const auto [ours, ccx] = both(dir, two_solid_bar(dir).string() +
                                         " --fix face:1 --modes 5 --order 2 --material "
                                         "solid:2=aluminium");
  expect_equal(ours, ccx, 1e-6, "bar, m, hex20 = C3D20");
  const std::string deck = text_of(dir / "job.inp");
  EXPECT_NE(deck.find("*ELASTIC\n2.1e+11, 0.3\n*DENSITY\n7850\n"), std::string::npos) << deck;
}

TEST(CcxDeck, ADeckThatIsNotInpIsAOneLineError) {
  const fs::path dir = work_dir("bad");
  const test::CliRun r =
      test::run_command(std::string(HEXFEM_BINARY) + " modal " + two_solid_bar(dir).string() +
                        " --units mm --fix face:1 --ccx-deck " + (dir / "job.msh").string());
  EXPECT_TRUE(r.code == 1 || r.code == 2) << r.out;
  EXPECT_EQ(r.out.rfind("hexfem: error: --ccx-deck", 0), 0u) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_FALSE(fs::exists(dir / "job_mesh.inp"));
}

}  // namespace
}  // namespace hexfem
