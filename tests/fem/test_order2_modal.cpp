// `hexfem modal --order 2` end to end: the steel part's first frequencies against the
// independent Gmsh tet10 + CalculiX reference (validation/reference/steel_part.json), the report
// naming the order and formulations, and --order 3 a one-line error.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace hexfem {
namespace {

std::string run(const std::string& args, int* code) {
  FILE* p = popen((std::string(HEXFEM_BINARY) + " " + args + " 2>&1").c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (p && fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = p ? pclose(p) : -1;
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

TEST(Order2Modal, SteelPartAtH2WithinATenthOfAPercentOnF1F2) {
  const std::string src = HEXFEM_SOURCE_DIR;
  std::ifstream ref_in(src + "/validation/reference/steel_part.json");
  const nlohmann::json ref = nlohmann::json::parse(ref_in);
  int code = 0;
  const std::string out =
      run("modal " + src + "/models/steel_part.step --h 2 --fix face:8 --modes 4 --order 2 --json",
          &code);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find('{')));
  EXPECT_EQ(j["order"], 2);
  EXPECT_NE(j["elements"].get<std::string>().find("hex20"), std::string::npos);
  EXPECT_EQ(j["order2"]["straightened_cells"], 0);
  EXPECT_GT(j["order2"]["curved_nodes"], 0);
  for (int m = 0; m < 2; ++m) {
    const double f = j["modes"][m]["frequency_hz"], fr = ref["reference_hz"][m];
    EXPECT_LT(std::abs(f - fr) / fr, 1e-3) << "f" << m + 1 << " " << f << " vs " << fr;
  }
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
  EXPECT_NE(au["solver"]["reason"].get<std::string>().find("no DOF limit at order 2"),
            std::string::npos)
      << au["solver"]["reason"];
  for (int m = 0; m < 6; ++m) {
    const double fd = d["modes"][m]["frequency_hz"], fi = it["modes"][m]["frequency_hz"];
    EXPECT_LT(std::abs(fi - fd) / fd, 1e-6) << "f" << m + 1 << " " << fi << " vs " << fd;
  }
}

}  // namespace
}  // namespace hexfem
