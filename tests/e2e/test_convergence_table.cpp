// The Table-2 arithmetic of `hexfem converge` against hand-made sequences with known orders.
#include <gtest/gtest.h>

#include <cmath>

#include "app/convergence_table.hpp"

namespace hexfem {
namespace {

ConvergenceStudy quadratic_study(bool with_reference) {
  // f_i(h) = ref_i (1 + c_i h^2): the observed order is exactly 2 for every pair.
  ConvergenceStudy s;
  s.part = "synthetic";
  const std::vector<double> ref = {100.0, 250.0};
  const std::vector<double> c = {0.01, -0.02};
  for (double h : {2.0, 1.0, 0.5}) {
    ConvergenceRow row;
    row.h = h;
    for (int i = 0; i < 2; ++i) row.frequencies.push_back(ref[i] * (1 + c[i] * h * h));
    s.rows.push_back(row);
  }
  if (with_reference) s.reference = ref;
  return s;
}

TEST(ConvergenceTable, OrdersAndErrorsWithReference) {
  const ConvergenceStudy s = quadratic_study(true);
  EXPECT_NEAR(s.error(0, 0), 0.04, 1e-15);
  EXPECT_NEAR(s.error(2, 1), -0.005, 1e-15);
  EXPECT_NEAR(s.observed_order(1, 0), 2.0, 1e-12);
  EXPECT_NEAR(s.observed_order(2, 1), 2.0, 1e-12);
  EXPECT_TRUE(s.monotone(0));
  EXPECT_TRUE(s.monotone(1));
  EXPECT_TRUE(std::isnan(s.observed_order(0, 0)));
}

TEST(ConvergenceTable, OrderFromThreeRowsWithoutReference) {
  const ConvergenceStudy s = quadratic_study(false);
  EXPECT_TRUE(std::isnan(s.observed_order(1, 0)));
  EXPECT_NEAR(s.observed_order(2, 0), 2.0, 1e-12);
  EXPECT_TRUE(std::isnan(s.error(0, 0)));
}

// Sizes not in one ratio (the audit's cube at h = 5, 3.33, 2.5 read 3.64 for 1.99): f = 100 +
// h^2 at h = 4, 3, 2 gives differences -7 and -5, q = 7/5, and (16 - 9)/(9 - 4) = 7/5 holds for
// p = 2 exactly; the old log(q)/log(4/3) read 1.17. And h^-1 (growing differences): p = -1.
TEST(ConvergenceTable, OrderFromSizesInAnyRatio) {
  EXPECT_NEAR(order_of_three_sizes(4, 3, 2, 7.0 / 5.0), 2.0, 1e-10);
  EXPECT_NEAR(order_of_three_sizes(2, 1, 0.5, 4.0), 2.0, 1e-10);  // ratio 2: log(4)/log(2)
  const double q = (1.0 / 4 - 1.0 / 3) / (1.0 / 3 - 1.0 / 2);     // f = 100 + 1/h
  EXPECT_NEAR(order_of_three_sizes(4, 3, 2, q), -1.0, 1e-10);
  EXPECT_TRUE(std::isnan(order_of_three_sizes(4, 3, 2, -1.0)));  // the frequencies turn
  EXPECT_TRUE(std::isnan(order_of_three_sizes(2, 3, 1, 2.0)));   // sizes out of order

  ConvergenceStudy s;
  for (double h : {4.0, 3.0, 2.0}) {
    ConvergenceRow row;
    row.h = h;
    row.frequencies = {100 + h * h, 200 + 1 / h};
    s.rows.push_back(row);
  }
  EXPECT_NEAR(s.observed_order(2, 0), 2.0, 1e-10);
  EXPECT_NEAR(s.observed_order(2, 1), -1.0, 1e-10);
  const std::string text = convergence_text(s);
  EXPECT_NE(text.find("observed order (the last three sizes): f1 2.00 f2 -1.00"), std::string::npos)
      << text;
  EXPECT_NE(text.find("note: f2: the differences grow"), std::string::npos) << text;
  EXPECT_EQ(convergence_text(quadratic_study(false)).find("note:"), std::string::npos);
}

TEST(ConvergenceTable, NonMonotoneIsReported) {
  ConvergenceStudy s = quadratic_study(true);
  s.rows[2].frequencies[0] = 105.0;  // worse than h = 1 (101)
  EXPECT_FALSE(s.monotone(0));
}

// Every mode asked for (--modes 10) gets its columns, errors and order; at most six did before,
// outside the JSON.
TEST(ConvergenceTable, EveryModeAskedForIsShown) {
  ConvergenceStudy s;
  for (double h : {2.0, 1.0, 0.5}) {
    ConvergenceRow row;
    row.h = h;
    for (int i = 0; i < 10; ++i) row.frequencies.push_back((i + 1) * 100 * (1 + 0.01 * h * h));
    s.rows.push_back(row);
  }
  s.rows[1].frequencies.push_back(5000);  // one row with more: the columns are the common ones
  EXPECT_EQ(s.num_frequencies(), 10);
  EXPECT_NE(convergence_text(s).find("f10 2.00"), std::string::npos) << convergence_text(s);
  EXPECT_EQ(convergence_text(s).find("f11"), std::string::npos);
  EXPECT_NE(convergence_csv(s).find(",f10"), std::string::npos) << convergence_csv(s);
  EXPECT_NE(convergence_markdown(s).find("f10 (Hz)"), std::string::npos);
}

TEST(ConvergenceTable, TextMarkdownCsv) {
  const ConvergenceStudy s = quadratic_study(true);
  const std::string csv = convergence_csv(s);
  EXPECT_NE(csv.find("h,nodes,cells,H_nbr,H_vol,seconds,f1,err_f1,f2,err_f2"), std::string::npos);
  EXPECT_NE(csv.find("104.000000,4.000000e-02"), std::string::npos) << csv;
  EXPECT_NE(convergence_markdown(s).find("| 2 |"), std::string::npos);
  EXPECT_NE(convergence_text(s).find("f1 2.00 f2 2.00"), std::string::npos) << convergence_text(s);
}

// The cylinder at h = 6 and 4.5 gives the same mesh (its curvature bound sets the size), so the
// two rows' frequencies differ by rounding: their "order" was -62. No order is read from such a
// pair, and the text says which sizes gave the same mesh.
TEST(ConvergenceTable, NoOrderFromTwoSizesWithTheSameMesh) {
  ConvergenceStudy s = quadratic_study(false);
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    s.rows[r].nodes = 1000 * static_cast<long>(r + 1);
    s.rows[r].cells = 300 * static_cast<long>(r + 1);
  }
  EXPECT_NEAR(s.observed_order(2, 0), 2.0, 1e-12);
  s.rows[1].nodes = s.rows[0].nodes;
  s.rows[1].cells = s.rows[0].cells;
  for (std::size_t i = 0; i < s.rows[1].frequencies.size(); ++i)
    s.rows[1].frequencies[i] = s.rows[0].frequencies[i] * (1 + 1e-13);
  EXPECT_TRUE(s.same_mesh(1));
  EXPECT_FALSE(s.same_mesh(2));
  const double f = s.rows[1].frequencies[0];
  s.rows[1].frequencies[0] *= 1 + 1.7e-4;  // the same counts, another mesh (a cube at h 4 and 3)
  EXPECT_FALSE(s.same_mesh(1));
  s.rows[1].frequencies[0] = f;
  EXPECT_TRUE(std::isnan(s.observed_order(2, 0)));
  EXPECT_TRUE(s.monotone(0));
  EXPECT_NE(convergence_text(s).find("h = 1 gave the same mesh as h = 2"), std::string::npos)
      << convergence_text(s);
  s.reference = {100.0, 250.0};
  EXPECT_TRUE(std::isnan(s.observed_order(1, 0)));
  EXPECT_FALSE(std::isnan(s.observed_order(2, 0)));
}

}  // namespace
}  // namespace hexfem
