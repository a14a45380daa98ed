// Backtracking on a residual norm (fem/line_search.hpp), on scalar stand-ins for a Newton
// iterate: the kept step, the moves made and the final evaluation at the kept trial.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "coapt/fem/line_search.hpp"

namespace {

using coapt::fem::backtrack;

/// x = x0 + length δ with a residual norm given per step length.
struct Iterate {
  double length = 1;
  std::map<double, double> norm_at;
  std::vector<double> evaluated;  ///< the lengths evaluated, in order
  double evaluate() {
    evaluated.push_back(length);
    return norm_at.at(length);
  }
};

TEST(Backtracking, HalvesUntilTheNormFallsBelowThePreviousOne) {
  // |x − 1| from x0 = 0 with an overshooting δ = 8: |R| 7, 3, then 1 = the previous norm.
  Iterate x{1.0, {{1.0, 7.0}, {0.5, 3.0}, {0.25, 1.0}}, {}};
  const auto kept = backtrack(
      10, 1.0, 7.0, 1.0,
      [&](double from, double to) {
        EXPECT_EQ(from, x.length);
        x.length = to;
      },
      [&] { return x.evaluate(); });
  EXPECT_EQ(kept.length, 0.25);
  EXPECT_EQ(kept.norm, 1.0);
  EXPECT_EQ(x.length, 0.25);
  EXPECT_EQ(x.evaluated, (std::vector<double>{0.5, 0.25}));  // no extra evaluation
}

TEST(Backtracking, KeepsTheBestTrialAndEvaluatesThereAgain) {
  // Every trial stays above the previous norm 1; the best is the first halving.
  Iterate x{1.0, {{1.0, 10.0}, {0.5, 2.0}, {0.25, 3.0}}, {}};
  const auto kept = backtrack(
      2, 1.0, 10.0, 1.0, [&](double, double to) { x.length = to; }, [&] { return x.evaluate(); });
  EXPECT_EQ(kept.length, 0.5);
  EXPECT_EQ(kept.norm, 2.0);
  EXPECT_EQ(x.length, 0.5);
  EXPECT_EQ(x.evaluated, (std::vector<double>{0.5, 0.25, 0.5}));
}

TEST(Backtracking, LeavesANonFiniteFullStep) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Iterate x{0.5, {{0.5, nan}, {0.25, 4.0}, {0.125, 0.5}}, {}};
  const auto kept = backtrack(
      5, 0.5, nan, 1.0, [&](double, double to) { x.length = to; }, [&] { return x.evaluate(); });
  EXPECT_EQ(kept.length, 0.125);
  EXPECT_EQ(kept.norm, 0.5);
}

TEST(Backtracking, KeepsTheFullStepWhenNoHalvingIsAllowedOrNeeded) {
  Iterate x{1.0, {{1.0, 5.0}}, {}};
  const auto none = backtrack(
      0, 1.0, 5.0, 1.0, [&](double, double to) { x.length = to; }, [&] { return x.evaluate(); });
  EXPECT_EQ(none.length, 1.0);
  EXPECT_EQ(none.norm, 5.0);
  EXPECT_TRUE(x.evaluated.empty());
  const auto fine = backtrack(
      4, 1.0, 0.5, 1.0, [&](double, double to) { x.length = to; }, [&] { return x.evaluate(); });
  EXPECT_EQ(fine.length, 1.0);
  EXPECT_TRUE(x.evaluated.empty());
}

}  // namespace
