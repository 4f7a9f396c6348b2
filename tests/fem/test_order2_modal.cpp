// `hexfem modal --order 2` end to end: the steel part's first frequencies against the
// independent Gmsh tet10 + CalculiX reference (validation/reference/steel_part.json), the report
// naming the order and formulations, and --order 3 a one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace hexfem {
namespace {

// Runs a shell command with stderr merged; its output, the exit code in *code.
std::string shell(const std::string& command, int* code) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (p && fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = p ? pclose(p) : -1;
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

std::string run(const std::string& args, int* code) {
  return shell(std::string(HEXFEM_BINARY) + " " + args, code);
}

// Frequencies first .. first + modes - 1 of a modal JSON against f1.. of a reference file in
// validation/reference/: above it by less than max_above, below it by less than max_below (by
// default the reference's own uncertainty).
void expect_reference(const nlohmann::json& j, const std::string& file, int first, int modes,
                      double max_above, double max_below = -1) {
  std::ifstream ref_in(std::string(HEXFEM_SOURCE_DIR) + "/validation/reference/" + file);
  const nlohmann::json ref = nlohmann::json::parse(ref_in);
  for (int m = 0; m < modes; ++m) {
    const double f = j["modes"][first + m]["frequency_hz"], fr = ref["reference_hz"][m];
    const double below =
        max_below >= 0 ? max_below : ref["reference_uncertainty_rel"][m].get<double>();
    EXPECT_GT(f / fr - 1, -below) << "f" << first + m + 1 << " " << f << " vs " << fr;
    EXPECT_LT(f / fr - 1, max_above) << "f" << first + m + 1 << " " << f << " vs " << fr;
  }
}

// The steel part's first `modes` frequencies (validation/reference/steel_part.json): not below it
// by more than its uncertainty, above it by less than max_rel.
void expect_steel_reference(const nlohmann::json& j, int modes, double max_rel) {
  expect_reference(j, "steel_part.json", 0, modes, max_rel);
}

// With the NC faces' hanging nodes on their quads (place_hanging_nodes_on_quads) the order-2 mesh
// is nearly conforming, so its frequencies bound the reference from above: before, nodes left
// off the twisted quads made f3 0.078 % low at h = 2, below the reference's uncertainty.
TEST(Order2Modal, SteelPartAtH2BoundsTheReferenceWithinAQuarterPercent) {
  const std::string src = HEXFEM_SOURCE_DIR;
  int code = 0;
  const std::string out =
      run("modal " + src +
              "/models/steel_part.step --h 2 --fix face:8 --modes 4 --order 2 --curvature 0 --json",
          &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(j["order"], 2);
  EXPECT_NE(j["elements"].get<std::string>().find("hex20"), std::string::npos);
  EXPECT_EQ(j["order2"]["straightened_cells"], 0);
  EXPECT_GT(j["order2"]["curved_nodes"], 0);
  EXPECT_GT(j["order2"]["hanging_placed"], 0);
  // Memory per stage: the peak when the mesh was done, then the whole run's (never lower).
  const double mesh_peak = j["mesh"]["peak_memory_bytes"];
  EXPECT_GT(mesh_peak, 1e6);
  EXPECT_LE(mesh_peak, j["solver"]["peak_memory_bytes"].get<double>());
  expect_steel_reference(j, 4, 2.5e-3);
}

// The order-2 default meshes curved faces with 12 elements per turn (never finer than h/2): on the
// steel part that refines the R3 fillet at the step, where the bending stress peaks, and brings
// f1 and f2 at h = 2 within the 0.1 % of issue 12 (+0.176 % and +0.097 % without it), still from
// above. The reference: Gmsh tet10 + CalculiX, Richardson-extrapolated.
TEST(Order2Modal, SteelPartAtH2IsWithinATenthOfAPercentWithTheDefaultCurvatureBound) {
  const std::string src = HEXFEM_SOURCE_DIR;
  int code = 0;
  const std::string out =
      run("modal " + src + "/models/steel_part.step --h 2 --fix face:8 --modes 2 --json", &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(j["order"], 2);
  EXPECT_EQ(j["mesh"]["curvature_bound"], 12);
  expect_steel_reference(j, 2, 1e-3);
  // --curvature 0 turns the bound off; a bound below 3 per turn is refused in one line.
  const std::string off = run("modal " + src +
                                  "/models/steel_part.step --h 4 --fix face:8 --modes 1 "
                                  "--curvature 0 --json",
                              &code);
  ASSERT_EQ(code, 0) << off;
  EXPECT_EQ(nlohmann::json::parse(off.substr(off.find('{')))["mesh"]["curvature_bound"], 0);
  const std::string bad =
      run("modal " + src + "/models/steel_part.step --h 4 --fix face:8 --curvature 2", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(bad.find("--curvature must be 0 (off) or at least 3"), std::string::npos) << bad;
}

// The cylinder at h = 2, against the graded C3D20 O-grid reference of validation/order2.md
// section 5 (f1 = f2 = 5182.13, f3 18868.58, f4 25552.97 Hz). With hanging nodes left free (off
// their twisted quads) the mesh came out too soft: f3, torsion, 0.33 % below, f1 below too. Now
// each NC face whose node cannot be tied is made conformal, so the mesh is an upper bound:
// every f from above, within 0.2 %, and torsion (no clamp singularity) within 0.01 %.
TEST(Order2Modal, CylinderIsAnUpperBoundOnceUntiedFacesAreConformal) {
  int code = 0;
  const std::string out = run("modal " + std::string(HEXFEM_TEST_DATA) +
                                  "/cylinder.stp --h 2 --fix 'y<177.501' --modes 4 "
                                  "--order 2 --json",
                              &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_GT(j["order2"]["hanging_placed"], 0);
  EXPECT_GT(j["order2"]["nc_made_conformal"], 0);
  EXPECT_EQ(j["order2"]["hanging_kept"], 0);
  const double ref[4] = {5182.13, 5182.13, 18868.58, 25552.97};
  for (int m = 0; m < 4; ++m) {
    const double f = j["modes"][m]["frequency_hz"];
    EXPECT_GT(f / ref[m] - 1, -1e-4) << "f" << m + 1 << " " << f << " vs " << ref[m];
    EXPECT_LT(f / ref[m] - 1, m == 2 ? 1e-4 : 2e-3) << "f" << m + 1 << " " << f << " vs " << ref[m];
  }
}

// The cylinder free-free at h = 4 (2,811 DOF, two cells across the radius), against the uniform
// C3D20 O-grid reference (validation/reference/cylinder_free_c20.json). One cell comes out of
// the curving valid but far from affine (min/max det J below 0.05); straightened, as it was
// until the threshold became 1e-4, it left a flat spot on the round face and f7 0.23 % low. Kept
// curved, each of f7-f10 is within 0.02 % (the tet10 chain: 0.08 % at 3,459 DOF).
TEST(Order2Modal, CoarseFreeCylinderKeepsItsValidCurvedCells) {
  int code = 0;
  const std::string out =
      run("modal " + std::string(HEXFEM_TEST_DATA) + "/cylinder.stp --h 4 --free --modes 10 --json",
          &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(j["order"], 2);
  EXPECT_EQ(j["order2"]["straightened_cells"], 0);
  expect_reference(j, "cylinder_free_c20.json", 6, 4, 2e-4, 2e-4);  // |f / fr - 1| < 2e-4
}

// The cube of issue 12's comparison (validation/order2.md section 4, box_free): meshed with
// hexes alone, its first four elastic frequencies at 8k DOF lie above the chain's extrapolated
// reference (reference/box_free.json) by less than 0.03 % (0.015 % measured), where the tet10
// chain needs 8.5k DOF for 0.117 %.
TEST(Order2Modal, FreeCubeOfHex20IsWithinThreeHundredthsOfAPercentAt8kDof) {
  int code = 0;
  const std::string out =
      run("modal " + std::string(HEXFEM_TEST_DATA) + "/box.stp --h 0.125 --free --modes 10 --json",
          &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(j["order"], 2);
  EXPECT_EQ(j["mesh"]["hex8"], 512);
  EXPECT_EQ(j["mesh"]["tet4"], 0);
  expect_reference(j, "box_free.json", 6, 4, 3e-4);
}

// Order 2 is the default for a CAD part (validation/order2.md section 4); --order 1 still gives
// the paper's elements, and --hex8 without --order 1 is refused rather than ignored.
TEST(Order2Modal, OrderTwoIsTheDefaultForACadPart) {
  const std::string part =
      std::string(HEXFEM_SOURCE_DIR) + "/models/steel_part.step --h 4 --fix face:8 --modes 2 ";
  int code = 0;
  const std::string two = run("modal " + part + "--json", &code);
  ASSERT_EQ(code, 0) << two;
  EXPECT_EQ(nlohmann::json::parse(two.substr(two.find('{')))["order"], 2);
  const std::string one = run("modal " + part + "--order 1 --hex8 full --json", &code);
  ASSERT_EQ(code, 0) << one;
  EXPECT_EQ(nlohmann::json::parse(one.substr(one.find('{')))["order"], 1);
  const std::string refused = run("modal " + part + "--hex8 full", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(refused.find("add --order 1"), std::string::npos) << refused;
  const std::string study = run("converge " + part + "--hex8 full", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(study.find("add --order 1"), std::string::npos) << study;
}

TEST(Order2Modal, OrderThreeIsAOneLineError) {
  int code = 0;
  const std::string out = run("modal " + std::string(HEXFEM_SOURCE_DIR) +
                                  "/models/steel_part.step --h 2 --fix face:8 --order 3",
                              &code);
  EXPECT_NE(code, 0);
  EXPECT_EQ(out, "hexfem: error: --order must be 1 or 2 (got 3)\n");
}

// The steel part at order 2 has NC faces whose hanging nodes both paths tie: the iterative path
// (its own assembly and eigensolver) equals the direct one; auto stays direct at order 2.
TEST(Order2Modal, IterativeTiesTheHangingNodesAsDirectDoes) {
  const std::string part = std::string(HEXFEM_SOURCE_DIR) + "/models/steel_part.step";
  int code = 0;
  const auto modes = [&](const std::string& solver) {
    const std::string out = run(
        "modal " + part + " --h 2 --fix face:8 --modes 6 --order 2 --solver " + solver + " --json",
        &code);
    EXPECT_EQ(code, 0) << out;
    return nlohmann::json::parse(out.substr(out.find('{')));
  };
  const nlohmann::json d = modes("direct"), it = modes("iterative"), au = modes("auto");
  EXPECT_GT(d["mesh"]["nc_quad_faces"].get<int>(), 0);
  EXPECT_EQ(it["solver"]["method"], "iterative");
  EXPECT_EQ(it["free_dofs"], d["free_dofs"]);
  EXPECT_EQ(au["solver"]["method"], "direct");
  EXPECT_NE(au["solver"]["reason"].get<std::string>().find("<= 300000 at order 2"),
            std::string::npos)
      << au["solver"]["reason"];
  for (int m = 0; m < 6; ++m) {
    const double fd = d["modes"][m]["frequency_hz"], fi = it["modes"][m]["frequency_hz"];
    EXPECT_LT(std::abs(fi - fd) / fd, 1e-6) << "f" << m + 1 << " " << fi << " vs " << fd;
  }
}

// The order-2 mesh `modal` writes with --mesh-out (hex20, wedge15, pyramid13, tet10 with their
// curved mid-edge nodes) read back by `modal`: the same DOFs and frequencies to 1e-10. Before,
// the reader refused every second-order type, and --order 1 on such a mesh gave the order-2
// answer.
TEST(Order2Modal, ItsOwnSecondOrderExportSolvesTheSame) {
  const std::string part = std::string(HEXFEM_SOURCE_DIR) + "/models/steel_part.step";
  const std::string msh = std::string(HEXFEM_WORK_DIR) + "/steel_order2_roundtrip.msh";
  int code = 0;
  std::string out =
      run("modal " + part + " --h 2 --fix face:8 --modes 4 --json --mesh-out " + msh, &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json cad = nlohmann::json::parse(out.substr(out.find('{')));
  out = run("modal " + msh + " --fix face:8 --modes 4 --json", &code);  // the file says mm
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json file = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(file["order"], 2);
  EXPECT_EQ(file["order2"]["mid_edge_nodes"], "as read");
  EXPECT_EQ(file["free_dofs"], cad["free_dofs"]);
  for (int m = 0; m < 4; ++m) {
    const double fc = cad["modes"][m]["frequency_hz"], ff = file["modes"][m]["frequency_hz"];
    EXPECT_LT(std::abs(ff - fc) / fc, 1e-10) << "f" << m + 1 << " " << ff << " vs " << fc;
  }
  // --order 1 on it solves its corners: the same as the first-order mesh meshio makes of it by
  // keeping each cell's corners (an independent path), fixed at x = 0 alike.
  const std::string lin = std::string(HEXFEM_WORK_DIR) + "/steel_order2_corners.msh";
  out = shell("/usr/bin/python3 " + std::string(HEXFEM_SOURCE_DIR) +
                  "/tests/data/order2_corners.py " + msh + " " + lin,
              &code);
  ASSERT_EQ(code, 0) << out;
  const auto first_order = [&](const std::string& mesh, const std::string& order) {
    const std::string o =
        run("modal " + mesh + " --units mm --fix 'x<0.001' --modes 4 --json" + order, &code);
    EXPECT_EQ(code, 0) << o;
    return nlohmann::json::parse(o.substr(o.find('{')));
  };
  const nlohmann::json lowered = first_order(msh, " --order 1"), corners = first_order(lin, "");
  EXPECT_EQ(lowered["order"], 1);
  EXPECT_EQ(lowered["free_dofs"], corners["free_dofs"]);
  for (int m = 0; m < 4; ++m) {
    const double fl = lowered["modes"][m]["frequency_hz"], fc = corners["modes"][m]["frequency_hz"];
    EXPECT_LT(std::abs(fl - fc) / fc, 1e-10) << "f" << m + 1 << " " << fl << " vs " << fc;
  }
}

// `hexfem mesh --order 2` reports the mesh it writes. The sphere at h = 1.247: NC faces whose
// hanging node cannot be tied are made conformal (more pyramids and tets than the order-1 mesh
// had), and the report's cell counts, NC count and volume are those `hexfem stats` finds in the
// written file; the volume, in both, is the curved cells' (the sphere's 3053.64 mm^3 to 1e-4),
// not the straight cells' (1 % less). With --no-pyramids no pyramid is written at all.
TEST(Order2Modal, MeshReportDescribesTheWrittenOrder2Mesh) {
  int code = 0;
  const std::string dir = std::string(HEXFEM_WORK_DIR);
  const std::string out =
      run("mesh " + std::string(HEXFEM_TEST_DATA) + "/sphere.stp --h 1.247 --order 2 --json -o " +
              dir + "/o2_sphere.msh",
          &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  ASSERT_GT(j["order2"]["nc_made_conformal"], 0);
  const std::string stats = run("stats --json " + dir + "/o2_sphere.msh", &code);
  ASSERT_EQ(code, 0) << stats;
  const nlohmann::json s = nlohmann::json::parse(stats.substr(stats.find('{')));
  EXPECT_EQ(j["cells"], s["cells_per_kind"]) << j["cells"] << " vs " << s["cells_per_kind"];
  EXPECT_EQ(j["nc_quads"], s["nonconformal_quads"]);
  const double sphere = 4.0 / 3.0 * M_PI * 9 * 9 * 9;  // radius 9 mm
  EXPECT_NEAR(j["mesh_volume"].get<double>() / sphere, 1, 1e-4);
  EXPECT_NEAR(s["volume"].get<double>(), j["mesh_volume"].get<double>(), 1e-9 * sphere);
  EXPECT_LT(j["volume_mixed"].get<double>() / sphere, 0.995);  // the straight cells'
  EXPECT_EQ(s["order"], 2);
  // "vertices" are the corners, as at order 1; with the mid-edge nodes, the file's nodes (the
  // corners and mid-edge nodes were counted together only when an NC face had been made
  // conformal: the interop audit).
  EXPECT_EQ(j["vertices"].get<long>() + j["order2"]["edge_nodes"].get<long>(),
            s["nodes"].get<long>());
  const std::string np = run("mesh " + std::string(HEXFEM_TEST_DATA) +
                                 "/sphere.stp --h 1.247 --order 2 --no-pyramids --json -o " + dir +
                                 "/o2_sphere_np.msh",
                             &code);
  ASSERT_EQ(code, 0) << np;
  const nlohmann::json jn = nlohmann::json::parse(np.substr(np.find('{')));
  EXPECT_EQ(jn["cells"]["pyramid5"], 0);
  EXPECT_GT(jn["order2"]["nc_left_untied"], 0);
  const std::string sn = run("stats --json " + dir + "/o2_sphere_np.msh", &code);
  const nlohmann::json sj = nlohmann::json::parse(sn.substr(sn.find('{')));
  EXPECT_EQ(sj["cells_per_kind"]["pyramid5"], 0);
  EXPECT_EQ(jn["vertices"].get<long>() + jn["order2"]["edge_nodes"].get<long>(),
            sj["nodes"].get<long>());
}

// A coarse sphere at order 2 whose straight cells are 19 % short of the CAD volume but whose
// curved cells are within 1 %: meshed and solved, not refused as too coarse.
TEST(Order2Modal, TheVolumeCheckReadsTheCurvedCells) {
  int code = 0;
  const std::string out = run("modal " + std::string(HEXFEM_TEST_DATA) +
                                  "/sphere.stp --h 6 --curvature 4 --free --modes 7 --json",
                              &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  const double sphere = 4.0 / 3.0 * M_PI * 9 * 9 * 9 * 1e-9;  // m^3
  EXPECT_NEAR(j["volume_m3"].get<double>() / sphere, 1, 0.01);
  EXPECT_NEAR(j["mesh"]["report"]["volume_error"].get<double>(), 0, 0.01);
  EXPECT_LT(j["mesh"]["report"]["volume_mixed"].get<double>() / (sphere * 1e9), 0.85);
}

}  // namespace
}  // namespace hexfem
