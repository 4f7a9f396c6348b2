// Order-2 exports read by the real readers: meshio reads MSH (types 17, 18, 19, 11 and the
// quad8/tri6 faces), VTU (quadratic cells) and INP (C3D20, C3D15, C3D10; pyramid13 as a collapsed
// C3D20) and every mid-edge node sits at its edge's midpoint in the format's own node order
// (tests/data/order2_readers.py); gmsh reads the MSH and finds every element's Jacobian positive.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <sstream>

#include "mesh_fixtures.hpp"
#include "mesher/high_order_nodes.hpp"
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

}  // namespace
}  // namespace hexfem
