// Real readers read what we write (meshio, gmsh), and we read what gmsh writes.
#include <gtest/gtest.h>

#include <map>
#include <regex>

#include "mesh_fixtures.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/mesh_stats.hpp"

namespace hexfem {
namespace {

using testing::run;
using testing::work_path;

// Cell counts per meshio cell type, from Debian's python3-meshio.
std::map<std::string, long> meshio_counts(const std::filesystem::path& p) {
  std::string out;
  const int rc =
      run("/usr/bin/python3 -c \"import meshio,sys; m=meshio.read(sys.argv[1]); "
          "import collections; c=collections.Counter(); "
          "[c.update({b.type: len(b.data)}) for b in m.cells]; "
          "[print(k, v) for k, v in c.items()]\" " +
              p.string(),
          &out);
  EXPECT_EQ(rc, 0) << out;
  std::map<std::string, long> counts;
  std::istringstream in(out);
  std::string type;
  long n;
  while (in >> type >> n) counts[type] = n;
  return counts;
}

TEST(ExternalReaders, MeshioReadsMshVtuInp) {
  // meshio 1.x rejects MSH files where only some entities carry physical tags (a meshio
  // limitation, the format allows it), so every face gets one here; the mesher writes none.
  MixedMesh m = testing::mixed_sample();
  m.bface_physical[1] = 200;
  m.length_unit = "mm";  // hexfem's own MSH section, which the reader must skip
  const std::map<std::string, long> cells = {
      {"hexahedron", 2}, {"pyramid", 1}, {"wedge", 1}, {"tetra", 1}};
  for (const char* name : {"meshio.msh", "meshio_bin.msh", "meshio.vtu", "meshio.inp"}) {
    const auto path = work_path(name);
    write_mesh(m, path, {std::string(name) == "meshio_bin.msh"});
    auto counts = meshio_counts(path);
    if (path.extension() == ".msh") {  // MSH also carries the boundary faces
      EXPECT_EQ(counts["quad"], 1) << name;
      EXPECT_EQ(counts["triangle"], 1) << name;
      counts.erase("quad");
      counts.erase("triangle");
    }
    if (path.extension() == ".inp") {
      // meshio reads Abaqus C3D8 as hexahedra: the pyramid (apex repeated) counts as one.
      EXPECT_EQ(counts["hexahedron"], 3) << name;
      counts["hexahedron"] -= 1;
      counts["pyramid"] += 1;
    }
    EXPECT_EQ(counts, cells) << name;
  }
}

TEST(ExternalReaders, GmshReadsOurMsh) {
  for (bool binary : {false, true}) {
    const auto path = work_path(binary ? "for_gmsh_bin.msh" : "for_gmsh.msh");
    MixedMesh m = testing::mixed_sample();
    m.length_unit = "mm";  // hexfem's own MSH section: skipped without a word
    write_msh(m, path, {binary});
    std::string out;
    EXPECT_EQ(
        run("gmsh -0 -v 2 " + path.string() + " -o " + work_path("gmsh_echo.msh").string(), &out),
        0)
        << out;
    EXPECT_EQ(out.find("rror"), std::string::npos) << out;
    EXPECT_EQ(out.find("arning"), std::string::npos) << out;
  }
}

struct GmshFacts {
  std::map<int, long> per_type;  // MSH element type -> count, as gmsh itself writes them
  double volume = 0;             // gmsh's Plugin(MeshVolume)
};

// Gmsh's own view of a mesh file: its MSH 2.2 re-export counted by type, and its volume.
GmshFacts gmsh_facts(const std::filesystem::path& msh) {
  GmshFacts f;
  const auto v22 = work_path(msh.stem().string() + "_v22.msh");
  EXPECT_EQ(run("gmsh -0 -v 0 " + msh.string() + " -format msh22 -o " + v22.string()), 0);
  std::ifstream in(v22);
  std::string line;
  while (std::getline(in, line) && line != "$Elements") {
  }
  long n = 0;
  in >> n;
  for (long i = 0; i < n; ++i) {
    long tag, type;
    in >> tag >> type;
    ++f.per_type[type];
    std::getline(in, line);
  }
  const auto geo = work_path(msh.stem().string() + "_vol.geo");
  const auto pos = work_path(msh.stem().string() + "_vol.pos");
  testing::write_file(geo, "Merge \"" + msh.string() +
                               "\";\nPlugin(MeshVolume).Dimension = 3;\n"
                               "Plugin(MeshVolume).Run;\nSave View[0] \"" +
                               pos.string() + "\";\n");
  std::string out;
  EXPECT_EQ(run("gmsh -0 -v 1 " + geo.string(), &out), 0) << out;
  // The view holds one scalar point, SP(x,y,z){volume}, written with full precision.
  std::ifstream view(pos);
  const std::string text((std::istreambuf_iterator<char>(view)), {});
  std::smatch m;
  EXPECT_TRUE(std::regex_search(text, m, std::regex(R"(SP\([^)]*\)\{([0-9.eE+-]+)\})"))) << text;
  if (!m.empty()) f.volume = std::stod(m[1]);
  return f;
}

void expect_stats_match_gmsh(const std::string& geo_text, const std::string& name) {
  const auto geo = work_path(name + ".geo");
  const auto msh = work_path(name + ".msh");
  testing::write_file(geo, geo_text);
  std::string out;
  ASSERT_EQ(run("gmsh -3 -v 1 " + geo.string() + " -format msh41 -o " + msh.string(), &out), 0)
      << out;
  const GmshFacts g = gmsh_facts(msh);
  const MeshStats s = compute_stats(read_msh(msh));
  EXPECT_EQ(static_cast<long>(s.cells_per_kind[int(CellKind::Tet4)]),
            g.per_type.count(4) ? g.per_type.at(4) : 0)
      << name;
  EXPECT_EQ(static_cast<long>(s.cells_per_kind[int(CellKind::Hex8)]),
            g.per_type.count(5) ? g.per_type.at(5) : 0)
      << name;
  EXPECT_EQ(static_cast<long>(s.cells_per_kind[int(CellKind::Wedge6)]),
            g.per_type.count(6) ? g.per_type.at(6) : 0)
      << name;
  EXPECT_EQ(static_cast<long>(s.cells_per_kind[int(CellKind::Pyramid5)]),
            g.per_type.count(7) ? g.per_type.at(7) : 0)
      << name;
  EXPECT_GT(s.num_cells, 0u);
  EXPECT_NEAR(s.volume, g.volume, 1e-9 * g.volume) << name;
  EXPECT_EQ(s.inverted, 0u) << name;
}

TEST(ExternalReaders, StatsMatchGmshOnHexMesh) {
  expect_stats_match_gmsh(
      "SetFactory(\"OpenCASCADE\");\nBox(1) = {0,0,0, 3,2,1};\nTransfinite Curve{:} = 5;\n"
      "Transfinite Surface{:};\nRecombine Surface{:};\nTransfinite Volume{1};\n",
      "gmsh_hex");
}

TEST(ExternalReaders, StatsMatchGmshOnExtrudedPrisms) {
  expect_stats_match_gmsh(
      "Mesh.MeshSizeMax = 0.3;\nPoint(1) = {0,0,0};\nPoint(2) = {2,0,0};\nPoint(3) = {1,1.5,0};\n"
      "Line(1) = {1,2};\nLine(2) = {2,3};\nLine(3) = {3,1};\nCurve Loop(1) = {1,2,3};\n"
      "Plane Surface(1) = {1};\nExtrude {0,0,1} { Surface{1}; Layers{4}; Recombine; }\n",
      "gmsh_prism");
}

TEST(ExternalReaders, StatsMatchGmshOnTets) {
  expect_stats_match_gmsh(
      "SetFactory(\"OpenCASCADE\");\nMesh.MeshSizeMax = 0.4;\nSphere(1) = {0,0,0, 1};\n",
      "gmsh_tet");
}

TEST(ExternalReaders, StatsMatchGmshOnMixedFile) {
  // One file: a hex block, a prism block from an extruded triangle mesh, and a tet block.
  expect_stats_match_gmsh(
      "Mesh.MeshSizeMax = 0.35;\n"
      "Point(1) = {0,0,0};\nPoint(2) = {1,0,0};\nPoint(3) = {1,1,0};\nPoint(4) = {0,1,0};\n"
      "Line(1) = {1,2};\nLine(2) = {2,3};\nLine(3) = {3,4};\nLine(4) = {4,1};\n"
      "Curve Loop(1) = {1,2,3,4};\nPlane Surface(1) = {1};\n"
      "Transfinite Curve{1,2,3,4} = 4;\nTransfinite Surface{1};\nRecombine Surface{1};\n"
      "Extrude {0,0,1} { Surface{1}; Layers{3}; Recombine; }\n"
      "Point(111) = {2,0,0};\nPoint(112) = {3,0,0};\nPoint(113) = {2.5,1,0};\n"
      "Line(111) = {111,112};\nLine(112) = {112,113};\nLine(113) = {113,111};\n"
      "Curve Loop(111) = {111,112,113};\nPlane Surface(111) = {111};\n"
      "Extrude {0,0,1} { Surface{111}; Layers{3}; Recombine; }\n"
      "Point(221) = {4,0,0};\nPoint(222) = {5,0,0};\nPoint(223) = {4.5,1,0};\n"
      "Line(221) = {221,222};\nLine(222) = {222,223};\nLine(223) = {223,221};\n"
      "Curve Loop(221) = {221,222,223};\nPlane Surface(221) = {221};\n"
      "Extrude {0,0,1} { Surface{221}; }\n",
      "gmsh_mixed");
}

}  // namespace
}  // namespace hexfem
