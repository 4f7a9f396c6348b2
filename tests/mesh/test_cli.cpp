// The stats and convert commands, and their one-line errors with non-zero exit codes.
#include <gtest/gtest.h>

#include "mesh_fixtures.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

using testing::hexfem_cli;
using testing::run;
using testing::work_path;

// Runs hexfem and expects failure with exactly one line that contains `needle`.
void expect_error(const std::string& args, const std::string& needle) {
  std::string out;
  const int rc = run(hexfem_cli() + " " + args, &out);
  EXPECT_NE(rc, 0) << args;
  EXPECT_NE(out.find("hexfem: error: "), std::string::npos) << out;
  EXPECT_NE(out.find(needle), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

TEST(Cli, HelpAndVersion) {
  std::string out;
  EXPECT_EQ(run(hexfem_cli() + " --help", &out), 0);
  EXPECT_NE(out.find("stats"), std::string::npos);
  EXPECT_NE(out.find("convert"), std::string::npos);
  EXPECT_EQ(run(hexfem_cli() + " --version", &out), 0);
  EXPECT_NE(out.find("hexfem " HEXFEM_VERSION), std::string::npos);
}

TEST(Cli, StatsTextAndJson) {
  write_msh(testing::hex_with_split_top(), work_path("cli_nc.msh"));
  std::string out;
  ASSERT_EQ(run(hexfem_cli() + " stats " + work_path("cli_nc.msh").string() + " --json", &out), 0)
      << out;
  EXPECT_NE(out.find("\"nonconformal_quads\": 1"), std::string::npos) << out;
  EXPECT_NE(out.find("\"watertight\": true"), std::string::npos) << out;
  ASSERT_EQ(run(hexfem_cli() + " stats " + work_path("cli_nc.msh").string(), &out), 0);
  EXPECT_NE(out.find("NC               100.00 %"), std::string::npos) << out;
}

TEST(Cli, ConvertWritesEachFormat) {
  write_msh(testing::mixed_sample(), work_path("cli_in.msh"));
  for (const char* ext : {"msh", "vtu", "inp"}) {
    const auto out_path = work_path(std::string("cli_out.") + ext);
    std::filesystem::remove(out_path);
    std::string out;
    EXPECT_EQ(
        run(hexfem_cli() + " convert " + work_path("cli_in.msh").string() + " " + out_path.string(),
            &out),
        0)
        << out;
    EXPECT_TRUE(std::filesystem::exists(out_path));
  }
}

TEST(Cli, BadInputGivesOneLineErrors) {
  expect_error("stats " + work_path("nope.msh").string(), "file not found");
  testing::write_file(work_path("cli_mesh.xyz"), "1 2 3\n");
  expect_error("stats " + work_path("cli_mesh.xyz").string(), "unknown mesh format");
  write_msh(testing::mixed_sample(), work_path("cli_good.msh"));
  expect_error(
      "convert " + work_path("cli_good.msh").string() + " " + work_path("cli_out.obj").string(),
      "unknown output format");
  testing::write_file(work_path("cli_trunc.msh"),
                      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n");
  expect_error("stats " + work_path("cli_trunc.msh").string(), "cli_trunc.msh:5:");
  // A surface-only mesh: no volume elements.
  MixedMesh surface;
  surface.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  surface.add_bface(0, 1, 2, -1, 1);
  write_msh(surface, work_path("cli_surface.msh"));
  expect_error("stats " + work_path("cli_surface.msh").string(), "no volume elements");
}

}  // namespace
}  // namespace hexfem
