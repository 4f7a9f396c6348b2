// Singular edges (mesher/singular_edges.hpp) and edge sizes (--size-at edge:ID=S): checked on an
// L-shaped block whose one inner corner is counted by hand, against a box (no inner corner),
// and by counting the surface points on a sized edge (its length over the size).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <utility>

#include "cad_test_util.hpp"
#include "mesher/cad/cad_model.hpp"
#include "mesher/singular_edges.hpp"
#include "mesher/surface_pipeline.hpp"

namespace hexfem {
namespace {

using cadtest::data;

// l_block.step: a 20 x 10 x 10 box with a 10 x 10 x 10 box on its left half
// (tests/data/SOURCES.md). Its only re-entrant edge is the inner corner of the L: x = 10, z = 10, y
// from 0 to 10.
bool is_inner_corner(const CadModel& cad, int e) {
  for (int v : cad.edge_vertices(e)) {
    const Vec3 p = cad.vertex_point(v);
    if (std::abs(p[0] - 10) > 1e-6 || std::abs(p[2] - 10) > 1e-6) return false;
  }
  return true;
}

// The reference frequencies of validation/reference/NAME.
nlohmann::json reference_hz(const std::string& name) {
  std::ifstream in(std::string(HEXFEM_SOURCE_DIR) + "/validation/reference/" + name);
  return nlohmann::json::parse(in)["reference_hz"];
}

// The JSON of a CLI run that must succeed.
nlohmann::json run_json(const std::string& args) {
  int rc = 0;
  nlohmann::json j = cadtest::run_cli_json(args, &rc);
  EXPECT_EQ(rc, 0) << args << "\n" << j;
  return j;
}

TEST(SingularEdges, TheInnerCornerOfAnLBlockIsItsOnlyReentrantEdge) {
  const CadModel cad = CadModel::read(data("l_block.step"));
  const std::vector<int> edges = reentrant_edges(cad);
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_TRUE(is_inner_corner(cad, edges[0]));
  // Twelve convex edges on a box, and none re-entrant.
  EXPECT_TRUE(reentrant_edges(CadModel::read(data("box.stp"))).empty());
  // A cylinder's seam and rims are not either.
  EXPECT_TRUE(reentrant_edges(CadModel::read(data("cylinder.stp"))).empty());
}

TEST(SingularEdges, TheRimOfFacesIsTheirEdgesThatBoundAFaceOutside) {
  const CadModel cad = CadModel::read(data("l_block.step"));
  // Face 4 is the bottom (z = 0, 20 x 10): its four edges. With face 5 (the end x = 20), the
  // edge they share is inside the region: 4 + 4 - 2 = 6.
  EXPECT_EQ(rim_edges(cad, {4}).size(), 4u);
  EXPECT_EQ(rim_edges(cad, {4, 5}).size(), 6u);
  // Every face: no rim.
  std::vector<int> all;
  for (int f = 1; f <= cad.num_faces(); ++f) all.push_back(f);
  EXPECT_TRUE(rim_edges(cad, all).empty());
}

// Surface nodes on the inner-corner line.
std::size_t points_on_inner_corner(const SurfaceMesh& s) {
  std::size_t n = 0;
  for (const Vec3& p : s.mesh.nodes) n += std::abs(p[0] - 10) < 1e-9 && std::abs(p[2] - 10) < 1e-9;
  return n;
}

TEST(SingularEdges, AnEdgeSizeSetsTheSpacingAlongTheEdge) {
  const CadModel cad = CadModel::read(data("l_block.step"));
  const int e = reentrant_edges(cad).at(0);
  SurfaceOptions opt;
  opt.h = 2;
  // 10 mm at h = 2: 5 segments, 6 points; at 0.5 mm: 20 segments, 21 points.
  EXPECT_EQ(points_on_inner_corner(mesh_surface(cad, opt)), 6u);
  opt.edge_sizes = {{e, 0.5}};
  const SurfaceMesh fine = mesh_surface(cad, opt);
  EXPECT_EQ(points_on_inner_corner(fine), 21u);
  // The size grows back away from the edge: the far end face (x = 20) keeps about h.
  std::size_t far = 0;
  for (const Vec3& p : fine.mesh.nodes) far += std::abs(p[0] - 20) < 1e-9;
  EXPECT_LE(far, 40u);  // 10 x 10 face at h = 2: about 36 points
}

TEST(SingularEdges, BadEdgeSizesAndSingularSizesAreOneLineErrors) {
  const std::string part = data("l_block.step");
  cadtest::expect_one_line_error(
      "mesh " + part + " --h 2 --size-at edge:99=1 -o " + cadtest::work("se.msh").string(),
      "no edge 99 (the part has 18 edges)");
  const std::string modal = "modal " + part + " --h 2 --fix face:1 ";
  const std::string converge = "converge " + part + " --fix face:1 ";
  const char* range = "--singular-size must be a fraction of --h in [0, 1]";
  // -1 was the "not given" value inside: typed, it was taken as not given (a sweep found it).
  const std::pair<std::string, const char*> cases[] = {
      {modal + "--singular-size 2", range},
      {modal + "--singular-size -0.5", range},
      {modal + "--singular-size -1", range},
      {modal + "--curvature -1", "--curvature must be 0 (off) or at least 3"},
      {converge + "--h 2,4,1", "--h: the sizes must go from coarse to fine"},
      {converge + "--h 2,2", "each smaller than the last (2 then 2)"},
  };
  for (const auto& [command, error] : cases) cadtest::expect_one_line_error(command, error);
}

// The clamped round bar (cylinder.stp, clamped at y = 177.5), order 2, against the structured
// C3D20 reference (validation/reference/cylinder_c20.json, +-0.014 %): graded towards the clamp's
// rim, a mesh of half the DOF is more accurate than the uniform one (validation/order2.md,
// "Graded towards the singular edges": 7,350 DOF at 0.125 % against 15,630 at 0.139 %).
TEST(SingularEdges, GradedTowardsTheClampARoundBarNeedsFewerDofs) {
  const auto ref = reference_hz("cylinder_c20.json");
  auto max_error = [&](const nlohmann::json& j) {
    double e = 0;
    for (int m = 0; m < 4; ++m)
      e = std::max(
          e, std::abs(j["modes"][m]["frequency_hz"].get<double>() / ref[m].get<double>() - 1));
    return e;
  };
  const std::string base = "modal " + data("cylinder.stp") + " --fix 'y<177.501' --modes 4 --json";
  const auto uniform = run_json(base + " --h 2");
  const auto graded = run_json(base + " --h 5.66 --singular-size 0.25");
  // The clamp face is a disk: its rim is its one circle; a cylinder has no re-entrant edge.
  EXPECT_EQ(graded["mesh"]["singular_edges"]["clamp_rim"].size(), 1u);
  EXPECT_TRUE(graded["mesh"]["singular_edges"]["reentrant"].empty());
  EXPECT_FALSE(uniform["mesh"].contains("singular_edges"));
  EXPECT_LT(graded["free_dofs"].get<long>(), 0.6 * uniform["free_dofs"].get<long>());
  EXPECT_LT(max_error(graded), max_error(uniform));
  EXPECT_LT(max_error(graded), 0.0015);
}

// Without --singular-size, a CAD part at order 2 gets its re-entrant edges at 0.5 h and nothing
// else: not the rim of the clamped face (on the steel part that cost DOF and no error), and
// nothing at order 1 or with --singular-size 0.
TEST(SingularEdges, ReentrantEdgesAloneAreGradedByDefaultAtOrderTwo) {
  const int inner = reentrant_edges(CadModel::read(data("l_block.step"))).at(0);
  const std::string base = "modal " + data("l_block.step") + " --h 2 --fix face:4 --modes 4 --json";
  const auto by_default = run_json(base);
  const auto& graded = by_default["mesh"]["singular_edges"];
  EXPECT_EQ(graded["fraction_of_h"].get<double>(), 0.5);
  EXPECT_EQ(graded["reentrant"], nlohmann::json::array({inner}));
  EXPECT_TRUE(graded["clamp_rim"].empty());
  EXPECT_TRUE(graded["by_default"].get<bool>());
  const auto off = run_json(base + " --singular-size 0");
  EXPECT_FALSE(off["mesh"].contains("singular_edges"));
  EXPECT_LT(off["free_dofs"].get<long>(), by_default["free_dofs"].get<long>());
  const auto order1 = run_json(base + " --order 1");
  EXPECT_FALSE(order1["mesh"].contains("singular_edges"));
  // Given, it grades the clamped face's rim too: the bottom's four edges.
  const auto given = run_json(base + " --singular-size 0.25");
  EXPECT_EQ(given["mesh"]["singular_edges"]["fraction_of_h"].get<double>(), 0.25);
  EXPECT_EQ(given["mesh"]["singular_edges"]["clamp_rim"].size(), 4u);
  EXPECT_FALSE(given["mesh"]["singular_edges"]["by_default"].get<bool>());
}

// The housing gehause_rohteil, free-free (34 re-entrant edges), against the tet10 chain's
// extrapolation (validation/reference/gehause_free.json, +-0.15-0.23 %): by default at h = 0.93
// (75,294 DOF) its first four elastic frequencies are each lower than the uniform mesh's at
// h = 0.7 (94,431 DOF), that is nearer the converged values, which both approach from above
// (validation/order2.md, "Re-entrant edges graded by default": max error 0.42 % against 0.59 %).
TEST(SingularEdges, TheGradedHousingIsMoreAccurateWithFewerDofs) {
  const auto ref = reference_hz("gehause_free.json");
  const std::string base = "modal " + data("gehause_rohteil.stp") + " --free --modes 10 --json";
  const auto graded = run_json(base + " --h 0.93");
  const auto uniform = run_json(base + " --h 0.7 --singular-size 0");
  EXPECT_EQ(graded["mesh"]["singular_edges"]["reentrant"].size(), 34u);
  EXPECT_LT(graded["free_dofs"].get<long>(), uniform["free_dofs"].get<long>());
  for (int k = 0; k < 4; ++k) {
    const double f_ref = ref[k].get<double>();
    const double fg = graded["modes"][6 + k]["frequency_hz"].get<double>();
    const double fu = uniform["modes"][6 + k]["frequency_hz"].get<double>();
    EXPECT_GT(fg, f_ref * 0.998) << "elastic mode " << k + 1;  // above, within the reference
    EXPECT_LT(fg, fu) << "elastic mode " << k + 1;
  }
}

// The clamp face graded to 0.15 h at h = 2: two rows of the cylinder's points at the same angles
// make a flat tet of four surface nodes (a planar rectangle) that no flip or lift removes, and the
// mesher refused ("1 flat cells"). Now the pipeline runs again with an interior point beside it
// (points_beside_flat_tets): a valid mesh of the CAD volume (the mesher writes none with a flat
// or inverted cell), the same bytes on every run. The points as before session 29 (no
// relaxation, the field's edge sizes): the default's points make no flat tet here.
TEST(SingularEdges, AFlatTetOfFourSurfaceNodesIsMeshedAgainWithAPointBeside) {
  const std::string args =
      "mesh " + data("cylinder.stp") +
      " --h 2 --size-at face:3=0.15h --relax-points 0 --no-edge-spacing-size --json -o ";
  int rc = 0;
  const auto j = cadtest::run_cli_json(args + cadtest::work("flat1.msh").string(), &rc);
  ASSERT_EQ(rc, 0) << j;
  EXPECT_GE(j["flat_retry_points"].get<int>(), 1);
  EXPECT_EQ(j["inverted"].get<int>(), 0);
  EXPECT_LT(std::abs(j["volume_error"].get<double>()), 0.01);
  cadtest::run_cli_json(args + cadtest::work("flat2.msh").string(), &rc);
  ASSERT_EQ(rc, 0);
  EXPECT_EQ(cadtest::file_bytes(cadtest::work("flat1.msh")),
            cadtest::file_bytes(cadtest::work("flat2.msh")));
}

// NIST CTC 01 at h = 7.75 (its diagonal / 120): one flat tet, then, with a point beside it,
// three elsewhere (TetGen orders co-spherical points differently with one point more), then two,
// then none: the points accumulate over up to four runs (the points as before session 29, as
// above, and every front at once as before session 31).
TEST(SingularEdges, FlatTetsThatMoveElsewhereAreRetriedUntilNoneIsLeft) {
  int rc = 0;
  const auto j = cadtest::run_cli_json("mesh " + data("0083_nist_ctc_01_asme1_ap242_colored.stp") +
                                           " --h 7.75045 --relax-points 0 --no-edge-spacing-size "
                                           "--no-coherent-first --json -o " +
                                           cadtest::work("nist120.msh").string(),
                                       &rc);
  ASSERT_EQ(rc, 0) << j;
  EXPECT_GE(j["flat_retry_points"].get<int>(), 2);
  EXPECT_EQ(j["inverted"].get<int>(), 0);
  EXPECT_LT(std::abs(j["volume_error"].get<double>()), 0.01);
}

}  // namespace
}  // namespace hexfem
