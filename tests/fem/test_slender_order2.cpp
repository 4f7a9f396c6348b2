// An order-2 slender part free-free (tie_rod, 120 x 12.7 x 8.9 mm), where two things failed: the
// direct path refused exact rigid-body modes (their round-off, in K's scale, was judged against
// the first elastic eigenvalue, 1e6 times smaller), and GAMG on the order-2 matrix preconditioned
// LOBPCG poorly (149 iterations). The two paths are independent solvers of the same matrices.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fem_test_util.hpp"

namespace hexfem {
namespace {

namespace fs = std::filesystem;

nlohmann::json modal_json(const std::string& args) {
  const test::CliRun r =
      test::run_command(std::string(HEXFEM_BINARY) + " modal " + args + " --json 2>/dev/null");
  EXPECT_EQ(r.code, 0) << args << "\n" << r.out;
  return r.code == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
}

std::vector<double> frequencies(const nlohmann::json& j) {
  std::vector<double> f;
  for (const auto& m : j["modes"]) f.push_back(m["frequency_hz"].get<double>());
  return f;
}

TEST(SlenderOrder2, DirectAndIterativeAgreeFreeFree) {
  const fs::path dir = fs::path(HEXFEM_WORK_DIR) / "slender_order2";
  fs::create_directories(dir);
  const std::string msh = (dir / "tie_rod.msh").string();
  const test::CliRun m =
      test::run_command(std::string(HEXFEM_BINARY) + " mesh " + HEXFEM_TEST_DATA +
                        "/tie_rod.step --h 12 --curvature 24 -o " + msh);
  ASSERT_EQ(m.code, 0) << m.out;
  // Order 2 from the .msh: straight mid-edge nodes, NC faces' hanging nodes tied.
  const std::string args = msh + " --units mm --order 2 --free --modes 8";
  const nlohmann::json direct = modal_json(args + " --solver direct");
  const nlohmann::json iterative = modal_json(args + " --solver iterative");
  ASSERT_FALSE(direct.is_null());
  ASSERT_FALSE(iterative.is_null());
  const std::vector<double> fd = frequencies(direct), fi = frequencies(iterative);
  ASSERT_EQ(fd.size(), 8u);
  ASSERT_EQ(fi.size(), 8u);
  for (int k = 0; k < 6; ++k) {
    EXPECT_LT(std::abs(fd[k]), 1e-4 * fd[6]) << "rigid mode " << k + 1;
    EXPECT_LT(std::abs(fi[k]), 1e-4 * fi[6]) << "rigid mode " << k + 1;
  }
  for (int k = 6; k < 8; ++k) EXPECT_NEAR(fi[k] / fd[k], 1.0, 1e-8) << "f" << k + 1;
  EXPECT_LT(direct["solver"]["max_residual"].get<double>(), 1e-6);
  // GAMG on the order-2 matrix took 149 iterations here; on the order-1 space below it, 67.
  const int iterations = iterative["solver"]["iterations"].get<int>();
  EXPECT_LT(iterations, 100);
  std::printf(
      "tie_rod h 12 order 2, %d DOF: f7 f8 %.4f %.4f Hz (direct), iterative within "
      "%.1e in %d iterations\n",
      direct["free_dofs"].get<int>(), fd[6], fd[7],
      std::max(std::abs(fi[6] / fd[6] - 1), std::abs(fi[7] / fd[7] - 1)), iterations);
}

}  // namespace
}  // namespace hexfem
