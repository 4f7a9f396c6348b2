// MSH round trips and reader errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "mesh_fixtures.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

using testing::work_path;
using testing::write_file;

std::string error_of(const std::filesystem::path& p);

void expect_same_mesh(const MixedMesh& a, const MixedMesh& b) {
  EXPECT_EQ(a.nodes, b.nodes);  // bitwise: ASCII uses shortest round-trip doubles
  EXPECT_EQ(a.cell_kind, b.cell_kind);
  EXPECT_EQ(a.cell_nodes, b.cell_nodes);
  EXPECT_EQ(a.cell_solid, b.cell_solid);
  EXPECT_EQ(a.cell_physical, b.cell_physical);
  EXPECT_EQ(a.bface_nodes, b.bface_nodes);
  EXPECT_EQ(a.bface_cad_face, b.bface_cad_face);
  EXPECT_EQ(a.bface_physical, b.bface_physical);
  EXPECT_EQ(a.physical_names, b.physical_names);
  EXPECT_EQ(a.length_unit, b.length_unit);
}

TEST(MshIo, RoundTripAsciiAndBinary) {
  MixedMesh m = testing::mixed_sample();
  m.nodes[15] = {1.0 / 3.0, 0.1 + 0.2, -2.5e-300};  // values that need all 17 digits
  for (bool binary : {false, true}) {
    const auto path = work_path(binary ? "roundtrip_bin.msh" : "roundtrip_ascii.msh");
    write_msh(m, path, {binary});
    const MixedMesh back = read_msh(path);
    expect_same_mesh(m, back);
    // And once more from what was read: a fixed point.
    write_msh(back, path, {binary});
    expect_same_mesh(m, read_msh(path));
  }
}

TEST(MshIo, TheLengthUnitComesBack) {
  for (const char* unit : {"mm", "m", ""}) {
    MixedMesh m = testing::mixed_sample();
    m.length_unit = unit;
    for (bool binary : {false, true}) {
      const auto path = work_path(binary ? "unit_bin.msh" : "unit_ascii.msh");
      write_msh(m, path, {binary});
      expect_same_mesh(m, read_msh(path));
    }
  }
  // A unit the reader does not know is an error naming it, not a silent metre.
  MixedMesh m = testing::mixed_sample();
  m.length_unit = "mm";
  write_msh(m, work_path("unit_inch.msh"));
  std::ifstream in(work_path("unit_inch.msh"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  text.replace(text.find("\nmm\n"), 4, "\ninch\n");
  write_file(work_path("unit_inch.msh"), text);
  EXPECT_NE(error_of(work_path("unit_inch.msh")).find("length unit 'inch' is not mm or m"),
            std::string::npos);
}

TEST(MshIo, BinaryAndAsciiAgree) {
  const MixedMesh m = testing::mixed_sample();
  write_msh(m, work_path("agree_a.msh"), {false});
  write_msh(m, work_path("agree_b.msh"), {true});
  expect_same_mesh(read_msh(work_path("agree_a.msh")), read_msh(work_path("agree_b.msh")));
}

TEST(MshIo, ReadsMsh22Ascii) {
  // Hand-written: a hex (physical 7, elementary 3) and one boundary quad, sparse node tags.
  write_file(work_path("v22.msh"),
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 7 \"body\"\n"
             "$EndPhysicalNames\n$Nodes\n8\n"
             "10 0 0 0\n20 1 0 0\n30 1 1 0\n40 0 1 0\n50 0 0 1\n60 1 0 1\n70 1 1 1\n80 0 1 1\n"
             "$EndNodes\n$Elements\n2\n1 3 2 5 4 10 40 30 20\n2 5 2 7 3 10 20 30 40 50 60 70 80\n"
             "$EndElements\n");
  const MixedMesh m = read_msh(work_path("v22.msh"));
  ASSERT_EQ(m.num_cells(), 1u);
  EXPECT_EQ(m.cell_kind[0], CellKind::Hex8);
  EXPECT_EQ(m.cell_solid[0], 3);
  EXPECT_EQ(m.cell_physical[0], 7);
  EXPECT_EQ(m.cell(0)[6], 6);
  ASSERT_EQ(m.num_bfaces(), 1u);
  EXPECT_EQ(m.bface_cad_face[0], 4);
  EXPECT_EQ(m.bface_physical[0], 5);
  EXPECT_EQ(m.physical_names.at({3, 7}), "body");
}

std::string error_of(const std::filesystem::path& p) {
  try {
    read_mesh(p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(MshIo, ErrorsNameTheProblemAndLine) {
  EXPECT_NE(error_of(work_path("does_not_exist.msh")).find("file not found"), std::string::npos);
  write_file(work_path("empty.msh"), "");
  EXPECT_NE(error_of(work_path("empty.msh")).find("empty"), std::string::npos);
  write_file(work_path("text.msh"), "hello world\n");
  EXPECT_NE(error_of(work_path("text.msh")).find("not a Gmsh MSH file"), std::string::npos);

  // Truncate a valid ASCII file inside $Nodes: the error names a line inside the file.
  write_msh(testing::mixed_sample(), work_path("full.msh"));
  std::ifstream in(work_path("full.msh"));
  std::string text((std::istreambuf_iterator<char>(in)), {});
  write_file(work_path("truncated.msh"), text.substr(0, text.find("$EndNodes") - 30));
  const std::string e = error_of(work_path("truncated.msh"));
  EXPECT_NE(e.find("truncated.msh:"), std::string::npos) << e;
  EXPECT_NE(e.find("end of file"), std::string::npos) << e;

  // Garbage in a number: the line of the bad token.
  std::string bad = text;
  bad.replace(bad.find("$Nodes\n") + 7, 1, "x");
  write_file(work_path("corrupt.msh"), bad);
  EXPECT_NE(error_of(work_path("corrupt.msh")).find("expected"), std::string::npos);

  // Truncated binary file.
  write_msh(testing::mixed_sample(), work_path("full_bin.msh"), {true});
  std::ifstream bin(work_path("full_bin.msh"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(bin)), {});
  write_file(work_path("truncated_bin.msh"), bytes.substr(0, bytes.size() / 2));
  EXPECT_NE(error_of(work_path("truncated_bin.msh")).find("truncated"), std::string::npos);

  std::filesystem::remove(work_path("mesh.stl"));
  EXPECT_NE(error_of(work_path("mesh.stl")).find("file not found"), std::string::npos);
  write_file(work_path("mesh.stl"), "solid x\n");
  EXPECT_NE(error_of(work_path("mesh.stl")).find("unknown mesh format"), std::string::npos);
}

TEST(MshIo, WritesAreAtomic) {
  // An unknown extension writes nothing; a failed write leaves no temporary file behind.
  const auto dir = work_path("atomic");
  std::filesystem::create_directories(dir);
  EXPECT_THROW(write_mesh(testing::mixed_sample(), dir / "x.obj"), Error);
  EXPECT_THROW(write_mesh(testing::mixed_sample(), dir / "missing_dir" / "x.msh"), Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

// CalculiX 2.20 refuses a real field over 20 characters ("*ERROR reading *NODE. Card image:
// 50,25.00000000000169,79.99999999999135,1.7763568394002505E-15", the glued AS1 assembly). The
// .inp writes the shortest round-trip form where it fits and else the most digits that do.
TEST(MshIo, InpCoordinatesFitCalculixFields) {
  MixedMesh m = testing::mixed_sample();
  m.nodes[3] = {1.7763568394002505e-15, -1.2345678901234567e-05, 25.00000000000169};
  m.nodes[4] = {1.0 / 3.0, -2.0 / 3.0, -2.5e-300};
  const auto path = work_path("fields.inp");
  write_mesh(m, path);
  std::ifstream in(path);
  std::string line;
  bool in_nodes = false;
  std::size_t checked = 0;
  while (std::getline(in, line)) {
    if (line.starts_with("*")) {
      in_nodes = line.starts_with("*NODE");
      continue;
    }
    if (!in_nodes) continue;
    std::stringstream row(line);
    std::string field;
    std::getline(row, field, ',');
    const std::size_t node = std::stoul(field) - 1;
    for (int a = 0; a < 3; ++a) {
      std::getline(row, field, ',');
      EXPECT_LE(field.size(), 20u) << line;
      const double x = m.nodes[node][a], back = std::stod(field);
      // 14 significant digits at worst (a sign, an exponent of two digits): 5e-14.
      EXPECT_LE(std::abs(back - x), 1e-13 * std::abs(x)) << line;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 3 * m.nodes.size());
}

}  // namespace
}  // namespace hexfem
