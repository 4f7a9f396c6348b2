// `hexfem recombine`: the recombination on tets made elsewhere. A box of cubes split into tets
// must come back as its cubes (counted by hand); Gmsh's own tets (one box, and two boxes sharing
// a face) give a valid mesh of their volume, the same bytes each run; bad inputs are one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/mesh/structured_box.hpp"
#include "mesher/tets_from_mesh.hpp"
#include "mesher/volume_pipeline.hpp"
#include "tests/fem/fem_test_util.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

fs::path work(const std::string& name) {
  const fs::path dir = fs::path(HEXFEM_WORK_DIR) / "recombine";
  fs::create_directories(dir);
  return dir / name;
}

test::CliRun hexfem(const std::string& args) {
  return test::run_command(std::string(HEXFEM_BINARY) + " " + args);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// n x n x n unit cubes, each split into six tets along its diagonal, with the boundary
// triangles tagged by box side; the node numbers reversed (interior nodes before surface ones)
// and every other tet given inside out, which the reader must undo.
MixedMesh cubes_of_tets(int n) {
  MixedMesh m = make_box_mesh({1.0 * n, 1.0 * n, 1.0 * n}, n, n, n, CellKind::Tet4);
  const auto nn = static_cast<std::int32_t>(m.nodes.size());
  std::reverse(m.nodes.begin(), m.nodes.end());
  for (std::int32_t& v : m.cell_nodes)
    if (v >= 0) v = nn - 1 - v;
  for (std::int32_t& v : m.bface_nodes)
    if (v >= 0) v = nn - 1 - v;
  for (std::size_t c = 0; c < m.num_cells(); c += 2)
    std::swap(m.cell_nodes[kMaxCellNodes * c + 1], m.cell_nodes[kMaxCellNodes * c + 2]);
  std::fill(m.cell_solid.begin(), m.cell_solid.end(), 1);
  return m;
}

TEST(RecombineInput, CubesSplitIntoTetsComeBackAsTheirCubes) {
  const int n = 3;
  const MixedMesh m = cubes_of_tets(n);
  ASSERT_EQ(m.num_cells(), 6u * n * n * n);
  TetsFromMesh in = tets_from_mesh(m);
  EXPECT_EQ(in.turned_tets, 3u * n * n * n);
  EXPECT_EQ(in.unused_nodes, 0u);
  // Surface nodes first: (n+1)^3 - (n-1)^3 of them.
  EXPECT_EQ(in.surface.mesh.nodes.size(), std::size_t((n + 1) * (n + 1) * (n + 1) - 8));
  VolumeReport r;
  const MixedMesh out = recombine_tets(std::move(in.tets), in.surface, {}, &r);
  std::size_t count[kNumCellKinds] = {};
  for (CellKind k : out.cell_kind) ++count[static_cast<int>(k)];
  EXPECT_EQ(count[static_cast<int>(CellKind::Hex8)], std::size_t(n * n * n));
  EXPECT_EQ(out.num_cells(), std::size_t(n * n * n));
  EXPECT_EQ(out.num_bfaces(), std::size_t(6 * n * n));  // each box side's n^2 squares
  const MeshStats s = compute_stats(out);
  EXPECT_DOUBLE_EQ(s.h_vol, 100.0);
  EXPECT_NEAR(s.volume, n * n * n, 1e-12);
  EXPECT_TRUE(s.watertight);
  EXPECT_EQ(s.inverted, 0u);

  // The same through the command line, from a file.
  write_mesh(m, work("cubes.msh"));
  const test::CliRun cli = hexfem("recombine " + work("cubes.msh").string() + " -o " +
                                  work("cubes_hex.msh").string() + " --json");
  ASSERT_EQ(cli.code, 0) << cli.out;
  const auto j = nlohmann::json::parse(cli.out);
  EXPECT_EQ(j["input"]["tets"], 6 * n * n * n);
  EXPECT_EQ(j["input"]["turned_tets"], 3 * n * n * n);
  EXPECT_DOUBLE_EQ(j["h_vol_percent"].get<double>(), 100.0);
  EXPECT_EQ(read_mesh(work("cubes_hex.msh")).num_cells(), std::size_t(n * n * n));
}

// Gmsh's tets of `geo` (gmsh -3, every element saved), recombined twice by the command line.
struct GmshRun {
  nlohmann::json report;
  std::string bytes, again;
};
GmshRun recombine_gmsh_tets(const std::string& name, const std::string& geo) {
  std::ofstream(work(name + ".geo")) << geo;
  const fs::path tets = work(name + "_tets.msh");
  const test::CliRun g = test::run_command("gmsh -3 -v 1 -format msh41 " +
                                           work(name + ".geo").string() + " -o " + tets.string());
  EXPECT_EQ(g.code, 0) << g.out;
  GmshRun r;
  const fs::path out = work(name + "_hexdom.msh");
  const test::CliRun c = hexfem("recombine " + tets.string() + " -o " + out.string() + " --json");
  EXPECT_EQ(c.code, 0) << c.out;
  if (c.code != 0) return r;
  r.report = nlohmann::json::parse(c.out);
  r.bytes = slurp(out);
  EXPECT_EQ(hexfem("recombine " + tets.string() + " -o " + out.string()).code, 0);
  r.again = slurp(out);
  return r;
}

TEST(RecombineInput, GmshTetsOfABoxGiveAValidMeshOfItsVolume) {
  const GmshRun r = recombine_gmsh_tets("box", R"(SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 10, 8, 6};
Mesh.MeshSizeMax = 1.5;
)");
  ASSERT_FALSE(r.report.is_null());
  EXPECT_EQ(r.report["inverted"], 0);
  EXPECT_NEAR(r.report["volume_mixed"].get<double>(), 480.0, 480.0 * 8e-4);
  EXPECT_GT(r.report["cells"]["hex8"].get<int>(), 0);
  EXPECT_EQ(r.bytes, r.again);  // same input, same output
  const MeshStats s = compute_stats(read_mesh(work("box_hexdom.msh")));
  EXPECT_TRUE(s.watertight);
  EXPECT_EQ(s.inverted, 0u);
}

TEST(RecombineInput, TwoVolumesSharingAFaceKeepTheirFaceAndIds) {
  const GmshRun r = recombine_gmsh_tets("two_boxes", R"(SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 6, 6, 6};
Box(2) = {6, 0, 0, 6, 6, 6};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.MeshSizeMax = 1.5;
)");
  ASSERT_FALSE(r.report.is_null());
  EXPECT_EQ(r.report["inverted"], 0);
  EXPECT_NEAR(r.report["volume_mixed"].get<double>(), 432.0, 432.0 * 8e-4);
  const MixedMesh m = read_mesh(work("two_boxes_hexdom.msh"));
  const MeshStats s = compute_stats(m);
  EXPECT_TRUE(s.watertight);
  // Both volumes, each about half the cells' volume; no boundary face on the shared plane.
  std::vector<std::int32_t> ids(m.cell_solid.begin(), m.cell_solid.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  EXPECT_EQ(ids, (std::vector<std::int32_t>{1, 2}));
  EXPECT_EQ(r.bytes, r.again);
}

void expect_error(const MixedMesh& m, const std::string& message) {
  try {
    tets_from_mesh(m);
    ADD_FAILURE() << "no error, expected: " << message;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

TEST(RecombineInput, WhatIsNotTetsWithTheirBoundaryIsRefusedByName) {
  MixedMesh hexes = make_box_mesh({2, 2, 2}, 2, 2, 2, CellKind::Hex8);
  expect_error(hexes, "is a hex8: recombine reads a mesh of tets only");
  MixedMesh no_boundary = cubes_of_tets(2);
  no_boundary.bface_nodes.clear();
  no_boundary.bface_cad_face.clear();
  no_boundary.bface_physical.clear();
  expect_error(no_boundary, "no boundary triangles");
  MixedMesh one_missing = cubes_of_tets(2);
  one_missing.bface_nodes.resize(one_missing.bface_nodes.size() - 4);
  one_missing.bface_cad_face.pop_back();
  one_missing.bface_physical.pop_back();
  expect_error(one_missing, "is not among the mesh's boundary triangles");
  MixedMesh untagged = cubes_of_tets(2);
  untagged.cell_solid[5] = 0;
  expect_error(untagged, "tet 6 has no volume entity");
  // A surface tag of -1 crashed the stages after TetGen, which index arrays by it (the fuzz,
  // seed 67); a wild one would ask for gigabytes.
  for (const std::int32_t tag : {-1, 0, 2000000000}) {
    MixedMesh bad_surface = cubes_of_tets(2);
    bad_surface.bface_cad_face[3] = tag;
    expect_error(bad_surface, "has surface tag " + std::to_string(tag));
  }
  MixedMesh wild_volume = cubes_of_tets(2);
  wild_volume.cell_solid[2] = 2000000000;
  expect_error(wild_volume, "tet 3 has volume tag 2000000000, above 1000000");

  // The command line: one line, exit 1, nothing written.
  write_mesh(hexes, work("hexes.msh"));
  fs::remove(work("never.msh"));
  const test::CliRun c =
      hexfem("recombine " + work("hexes.msh").string() + " -o " + work("never.msh").string());
  EXPECT_EQ(c.code, 1) << c.out;
  EXPECT_EQ(c.out.rfind("hexfem: error: ", 0), 0u) << c.out;
  EXPECT_EQ(std::count(c.out.begin(), c.out.end(), '\n'), 1) << c.out;
  EXPECT_FALSE(fs::exists(work("never.msh")));
}

}  // namespace
}  // namespace hexfem
