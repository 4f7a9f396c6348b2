// A material per CAD solid (an assembly of steel and aluminium parts): the solver against
// CalculiX with one material per element set on the same mesh, the mass by hand, the iterative
// path against the direct one, and the CLI's --material solid:IDS=... with its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fem/boundary.hpp"
#include "fem/modal_solver.hpp"
#include "fem_test_util.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/structured_box.hpp"
#include "tests/support/ccx_reference.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

const Material kSteel{"steel", 210e9, 0.3, 7850};
const Material kAluminium{"aluminium", 70e9, 0.33, 2700};

// 100 x 10 x 10 mm bar of 40 x 4 x 4 cells of `kind`: solid 1 (x < 50), solid 2 (x > 50).
MixedMesh two_solid_bar(CellKind kind) {
  MixedMesh mesh = make_box_mesh({100, 10, 10}, 40, 4, 4, kind);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    double x = 0;
    const int n = num_nodes(mesh.cell_kind[c]);
    for (int i = 0; i < n; ++i) x += mesh.nodes[mesh.cell(c)[i]][0] / n;
    mesh.cell_solid[c] = x < 50 ? 1 : 2;
  }
  return mesh;
}

ModalOptions steel_and_aluminium(int modes, std::vector<std::string> fix) {
  ModalOptions opt;
  opt.material = SolidMaterials(kSteel);
  opt.material.by_solid = {{2, kAluminium}};
  opt.fix = std::move(fix);
  opt.num_modes = modes;
  opt.length_scale = 1e-3;
  return opt;
}

TEST(SolidMaterials, SteelAndAluminiumBarMatchesCalculixOnTheSameMesh) {
  // Clamped at the steel end; hexfem's fully integrated hex8 is CalculiX's C3D8 (its other
  // linear elements integrate their mass differently: validation/crosscheck.md).
  for (CellKind kind : {CellKind::Hex8}) {
    const MixedMesh mesh = two_solid_bar(kind);
    const ModalOptions opt = steel_and_aluminium(6, {"face:1"});
    const ModalResult r = solve_modal(mesh, opt);
    // Mass by hand: each half is 50 x 10 x 10 mm = 5e-6 m^3.
    EXPECT_NEAR(r.total_mass, (7850 + 2700) * 5e-6, 1e-12);
    EXPECT_NEAR(r.volume, 1e-5, 1e-17);

    const fs::path dir = fs::path(HEXFEM_WORK_DIR) / "fem_ccx_two_materials";
    const std::string name = std::string("bar_") + kind_name(kind);
    const CcxRun ccx =
        run_ccx_frequency(mesh, select_fixed_dofs(mesh, opt.fix), opt.material, 6, dir, name, 1e-3);
    ASSERT_GE(ccx.output.frequencies.size(), 6u);
    for (int i = 0; i < 6; ++i) {
      std::printf("steel|aluminium bar %s mode %d: hexfem %.7f Hz, ccx %.7f Hz, rel. diff %.1e\n",
                  kind_name(kind), i + 1, r.frequencies[i], ccx.output.frequencies[i],
                  r.frequencies[i] / ccx.output.frequencies[i] - 1);
      EXPECT_NEAR(r.frequencies[i] / ccx.output.frequencies[i] - 1, 0.0, 1e-6)
          << kind_name(kind) << " mode " << i + 1;
    }
    // The same bar all steel is another structure: the aluminium half must show.
    ModalOptions all_steel = opt;
    all_steel.material.by_solid.clear();
    const ModalResult s = solve_modal(mesh, all_steel);
    EXPECT_GT(std::abs(s.frequencies[0] / r.frequencies[0] - 1), 0.05) << kind_name(kind);
  }
}

TEST(SolidMaterials, IterativePathTakesThemToo) {
  const MixedMesh mesh = two_solid_bar(CellKind::Hex8);
  ModalOptions opt = steel_and_aluminium(10, {});  // free-free: six rigid modes first
  opt.solver = SolverChoice::Direct;
  const ModalResult d = solve_modal(mesh, opt);
  opt.solver = SolverChoice::Iterative;
  const ModalResult it = solve_modal(mesh, opt);
  EXPECT_EQ(it.eigen.method, "iterative");
  EXPECT_NEAR(it.total_mass, d.total_mass, 1e-12 * d.total_mass);
  EXPECT_NEAR(it.volume, 1e-5, 1e-17);
  for (int i = 6; i < 10; ++i)
    EXPECT_NEAR(it.frequencies[i] / d.frequencies[i] - 1, 0.0, 1e-6) << "mode " << i + 1;
}

TEST(SolidMaterials, AMaterialForASolidTheMeshHasNotIsAnError) {
  const MixedMesh mesh = two_solid_bar(CellKind::Hex8);
  ModalOptions opt = steel_and_aluminium(4, {"face:1"});
  opt.material.by_solid = {{3, kAluminium}};
  try {
    solve_modal(mesh, opt);
    ADD_FAILURE() << "solid 3 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no such solid (its solids: 1, 2)"), std::string::npos)
        << e.what();
  }
}

using test::CliRun;

CliRun hexfem(const std::string& args) {
  return test::run_command(std::string(HEXFEM_BINARY) + " " + args);
}

std::string bar_msh() {
  static const fs::path p = [] {
    const fs::path dir = fs::path(HEXFEM_WORK_DIR) / "fem_cli";
    fs::create_directories(dir);
    const fs::path path = dir / "two_solid_bar.msh";
    MixedMesh mesh = two_solid_bar(CellKind::Hex8);
    write_mesh(mesh, path);
    return path;
  }();
  return p.string();
}

TEST(SolidMaterials, CliGivesSolidsTheirOwnMaterial) {
  const std::string base = "modal " + bar_msh() + " --units mm --fix face:1 --modes 3 --hex8 full";
  const CliRun r = hexfem(base + " --material solid:2=aluminium --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["mass_kg"].get<double>(), (7850 + 2700) * 5e-6, 1e-12);
  EXPECT_EQ(j["material"]["name"], "steel");
  ASSERT_EQ(j["material"]["solids"].size(), 1u);
  EXPECT_EQ(j["material"]["solids"][0]["solid"], 2);
  EXPECT_EQ(j["material"]["solids"][0]["name"], "aluminium");
  // The same through E, nu, rho given by value, and the solver's own result.
  const CliRun v = hexfem(base + " --material solid:2=70e9,0.33,2700 --json");
  ASSERT_EQ(v.code, 0) << v.out;
  const ModalResult direct =
      solve_modal(two_solid_bar(CellKind::Hex8), steel_and_aluminium(3, {"face:1"}));
  for (int i = 0; i < 3; ++i) {
    const double f = direct.frequencies[i];
    EXPECT_NEAR(j["modes"][i]["frequency_hz"].get<double>(), f, 1e-9 * f);
    EXPECT_NEAR(nlohmann::json::parse(v.out)["modes"][i]["frequency_hz"].get<double>(), f,
                1e-9 * f);
  }
  // The text report names both.
  const CliRun t = hexfem(base + " --material titanium --material solid:1-2=aluminium");
  ASSERT_EQ(t.code, 0) << t.out;
  EXPECT_NE(t.out.find("material  titanium"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("material  solid 1: aluminium"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("material  solid 2: aluminium"), std::string::npos) << t.out;
}

TEST(SolidMaterials, CliRefusesBadSpecsInOneLine) {
  const std::string base = "modal " + bar_msh() + " --units mm --fix face:1 --modes 3 ";
  std::vector<std::pair<std::string, std::string>> cases = {
      {"--material solid:3=aluminium", "no such solid (its solids: 1, 2)"},
      {"--material solid:x=steel", "expected solid ids like 2 or 1,4-6"},
      {"--material solid:0=steel", "expected solid ids like 2 or 1,4-6"},
      {"--material solid:2", "expected solid:IDS=NAME or solid:IDS=E,nu,rho"},
      {"--material solid:2=brass", "unknown material 'brass'"},
      {"--material solid:2=70e9,0.33", "expected a material name or E,nu,rho"},
      {"--material solid:2=70e9,0.7,2700", "Poisson's ratio nu must be in (-1, 0.5)"},
      {"--material steel --material aluminium", "a material for every solid is already given"},
      {"--material solid:2=steel --material solid:1-2=aluminium", "solid 2 is given two materials"},
  };
  // A CAD part: its solids are counted before any meshing.
  cases.push_back({"--material solid:2=aluminium CAD", "the CAD model has 1 solid(s), ids 1 to 1"});
  for (auto [args, message] : cases) {
    std::string command = base + args;
    if (args.ends_with(" CAD"))
      command = "modal " + std::string(HEXFEM_TEST_DATA) + "/box.stp --h 0.5 --free " +
                args.substr(0, args.size() - 4);
    const CliRun r = hexfem(command);
    EXPECT_TRUE(r.code == 1 || r.code == 2) << args << "\n" << r.out;
    EXPECT_EQ(r.out.rfind("hexfem: error: ", 0), 0u) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << args << "\n" << r.out;
  }
}

}  // namespace
}  // namespace hexfem
