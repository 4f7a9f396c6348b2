// Order-2 exports read by the real readers: meshio reads MSH (types 17, 18, 19, 11 and the
// quad8/tri6 faces), VTU (quadratic cells) and INP (C3D20, C3D15, C3D10; pyramid13 as a collapsed
// C3D20) and every mid-edge node sits at its edge's midpoint in the format's own node order
// (tests/data/order2_readers.py); gmsh reads the MSH and finds every element's Jacobian positive.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>

#include "mesh_fixtures.hpp"
#include "mesher/high_order_nodes.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/mesh_io.hpp"

namespace hexfem {
namespace {

using testing::run;
using testing::work_path;

MixedMesh order2_sample() {
  MixedMesh m = testing::mixed_sample();
  m.bface_physical[1] = 200;  // meshio wants every face tagged when some are (see test_external)
  add_mid_edge_nodes(m);
  return m;
}

struct ReadBack {
  std::map<std::string, long> count;
  double worst = 0;  // largest |mid-edge node - edge midpoint| / edge length
};

ReadBack meshio_read(const std::filesystem::path& p) {
  std::string out;
  const int rc =
      run("/usr/bin/python3 " + std::string(HEXFEM_TEST_DATA) + "/order2_readers.py " + p.string(),
          &out);
  EXPECT_EQ(rc, 0) << out;
  ReadBack r;
  std::istringstream in(out);
  std::string type, worst;
  long n;
  while (in >> type >> n >> worst) {
    r.count[type] += n;
    if (worst != "nan") r.worst = std::max(r.worst, std::stod(worst));
  }
  return r;
}

TEST(Order2Io, MeshioReadsMshVtuInpInTheirNodeOrder) {
  const MixedMesh m = order2_sample();
  const std::map<std::string, long> cells = {
      {"hexahedron20", 2}, {"pyramid13", 1}, {"wedge15", 1}, {"tetra10", 1}};
  for (const char* name : {"o2.msh", "o2_bin.msh", "o2.vtu", "o2.inp"}) {
    const auto path = work_path(name);
    write_mesh(m, path, {std::string(name) == "o2_bin.msh"});
    ReadBack r = meshio_read(path);
    EXPECT_LT(r.worst, 1e-12) << name;
    if (path.extension() == ".msh") {
      EXPECT_EQ(r.count["quad8"], 1) << name;
      EXPECT_EQ(r.count["triangle6"], 1) << name;
      r.count.erase("quad8");
      r.count.erase("triangle6");
    }
    if (path.extension() == ".inp") {  // the pyramid13 is a collapsed C3D20
      EXPECT_EQ(r.count["hexahedron20"], 3) << name;
      r.count["hexahedron20"] -= 1;
      r.count["pyramid13"] += 1;
    }
    EXPECT_EQ(r.count, cells) << name;
  }
}

TEST(Order2Io, GmshFindsEveryJacobianPositive) {
  const MixedMesh m = order2_sample();
  const auto msh = work_path("o2_gmsh.msh"), geo = work_path("o2_gmsh.geo");
  write_mesh(m, msh);
  testing::write_file(geo, "Merge \"" + msh.string() +
                               "\";\nPlugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                               "Plugin(AnalyseMeshQuality).CreateView = 0;\n"
                               "Plugin(AnalyseMeshQuality).Run;\n");
  std::string out;
  ASSERT_EQ(run("gmsh -0 -v 4 " + geo.string(), &out), 0) << out;
  // "minJ/maxJ =  worst, avg, best": every sample cell is affine, so with the right node order
  // each Jacobian is constant (1); a wrong order puts mid-edge nodes off their edges.
  const std::regex re(R"(minJ/maxJ =\s+([-0-9.eE+]+),\s+([-0-9.eE+]+),\s+([-0-9.eE+]+))");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(out, match, re)) << out;
  EXPECT_GT(std::stod(match[1].str()), 0.999) << out;
  EXPECT_NE(out.find("Volume 1: checking the Jacobian of 2 elements"), std::string::npos) << out;
  EXPECT_NE(out.find("Volume 2: checking the Jacobian of 3 elements"), std::string::npos) << out;
}

// Largest |mid-edge node - edge midpoint| over every cell edge and boundary face edge of `m`.
double worst_midpoint_offset(const MixedMesh& m) {
  double worst = 0;
  auto check = [&](std::int32_t a, std::int32_t b, std::int32_t mid) {
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(m.nodes[mid][c] - 0.5 * (m.nodes[a][c] + m.nodes[b][c])));
  };
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    for (int e = 0; e < num_edges(m.cell_kind[c]); ++e) {
      const auto& ed = edges_of(m.cell_kind[c])[e];
      check(m.cell(c)[ed[0]], m.cell(c)[ed[1]], m.cell_edges(c)[e]);
    }
  for (std::size_t f = 0; f < m.num_bfaces(); ++f) {
    const int n = m.bface_is_quad(f) ? 4 : 3;
    for (int i = 0; i < n; ++i)
      check(m.bface(f)[i], m.bface(f)[(i + 1) % n], m.bface_edge_nodes[4 * f + i]);
  }
  return worst;
}

// hexfem reads second-order MSH back: its own export gives the same arrays, and a Gmsh P2 mesh
// of a box (tet10, tri6 and line3 elements; every edge straight) puts each mid-edge node at the
// midpoint of the edge it belongs to in element_topology.hpp's order, which checks that order
// against Gmsh's own.
TEST(Order2Io, SecondOrderMshReadsBack) {
  const MixedMesh m = order2_sample();
  const auto own = work_path("o2_readback.msh");
  write_mesh(m, own);
  const MixedMesh back = read_mesh(own);
  EXPECT_EQ(back.order, 2);
  EXPECT_EQ(back.cell_nodes, m.cell_nodes);
  EXPECT_EQ(back.cell_edge_nodes, m.cell_edge_nodes);
  EXPECT_EQ(back.bface_nodes, m.bface_nodes);
  EXPECT_EQ(back.bface_edge_nodes, m.bface_edge_nodes);

  const auto geo = work_path("o2_box.geo"), msh = work_path("o2_box.msh");
  testing::write_file(geo,
                      "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 4, 2, 1};\n"
                      "Mesh.ElementOrder = 2;\nMesh.MeshSizeMax = 0.8;\nMesh.SaveAll = 1;\n");
  std::string out;
  ASSERT_EQ(run("gmsh -3 -format msh41 -o " + msh.string() + " " + geo.string(), &out), 0) << out;
  const MixedMesh g = read_mesh(msh);
  EXPECT_EQ(g.order, 2);
  ASSERT_GT(g.num_cells(), 10u);
  EXPECT_GT(g.num_bfaces(), 10u);
  EXPECT_LT(worst_midpoint_offset(g), 1e-9);
}

}  // namespace
}  // namespace hexfem
