// IQN-ILS (coupling/quasi_newton.hpp) on affine fixed-point maps H(x) = A x + b, whose fixed
// point x* = (I − A)⁻¹ b is known: IQN-ILS is then Newton's method on the span of its columns,
// so it finds x* in at most n + 1 evaluations in R^n even where plain iteration diverges, and
// with the columns of a past step reused it finds the fixed point of a new b at once (unless
// they are dropped).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <vector>

#include "coapt/coupling/quasi_newton.hpp"

namespace coapt::coupling {
namespace {

constexpr int kSize = 6;

/// A = a non-symmetric matrix with spectral radius > 1 (plain iteration diverges).
std::vector<double> matrix() {
  std::vector<double> a(kSize * kSize);
  for (int i = 0; i < kSize; ++i)
    for (int j = 0; j < kSize; ++j)
      a[i * kSize + j] = (i == j ? -1.5 : 0.0) + 0.1 * std::sin(1.0 + i + 2.0 * j);
  return a;
}

std::vector<double> apply(const std::vector<double>& a, const std::vector<double>& b,
                          const std::vector<double>& x) {
  std::vector<double> y(b);
  for (int i = 0; i < kSize; ++i)
    for (int j = 0; j < kSize; ++j) y[i] += a[i * kSize + j] * x[j];
  return y;
}

double residual_norm(const std::vector<double>& a, const std::vector<double>& b,
                     const std::vector<double>& x) {
  const auto y = apply(a, b, x);
  double sum = 0;
  for (int i = 0; i < kSize; ++i) sum += (y[i] - x[i]) * (y[i] - x[i]);
  return std::sqrt(sum);
}

/// Iterates until ‖H(x) − x‖ < 1e-10 (at most 50 evaluations); returns the evaluations.
int solve(InterfaceQuasiNewton& accelerator, const std::vector<double>& a,
          const std::vector<double>& b, std::vector<double>& x) {
  accelerator.begin_step();
  for (int evaluation = 1; evaluation <= 50; ++evaluation) {
    const auto x_tilde = apply(a, b, x);
    if (residual_norm(a, b, x) < 1e-10) return evaluation;
    std::vector<double> next(kSize);
    accelerator.next(x, x_tilde, 0.1, next);
    x = next;
  }
  return 51;
}

TEST(InterfaceQuasiNewton, FindsTheFixedPointOfAnAffineMapInNPlusTwoEvaluations) {
  const auto a = matrix();
  const std::vector<double> b = {1, -2, 0.5, 3, -1, 0.25};
  InterfaceQuasiNewton accelerator(MPI_COMM_SELF, 0, 50, 1e-12);
  std::vector<double> x(kSize, 0.0);
  const int evaluations = solve(accelerator, a, b, x);
  // one relaxed step, then at most n quasi-Newton steps, then the evaluation that checks
  EXPECT_LE(evaluations, kSize + 2);
  EXPECT_LT(residual_norm(a, b, x), 1e-10);
}

TEST(InterfaceQuasiNewton, ReusedColumnsSolveTheNextStepAtOnce) {
  const auto a = matrix();
  InterfaceQuasiNewton accelerator(MPI_COMM_SELF, 2, 50, 1e-12);
  std::vector<double> x(kSize, 0.0);
  solve(accelerator, a, {1, -2, 0.5, 3, -1, 0.25}, x);
  accelerator.end_step();
  // the same A, another b: the kept columns span R^n, so the first update is Newton's step
  const int evaluations = solve(accelerator, a, {0.3, 1, -1, 2, 0.5, -0.7}, x);
  EXPECT_LE(evaluations, 3);
  EXPECT_LT(residual_norm(a, {0.3, 1, -1, 2, 0.5, -0.7}, x), 1e-10);
}

TEST(InterfaceQuasiNewton, DroppedColumnsAreNotUsedAndForgottenAtTheStepsEnd) {
  const auto a = matrix();
  const std::vector<double> b = {1, -2, 0.5, 3, -1, 0.25};
  InterfaceQuasiNewton accelerator(MPI_COMM_SELF, 2, 50, 1e-12);
  std::vector<double> x(kSize, 0.0);
  solve(accelerator, a, b, x);
  accelerator.end_step();
  ASSERT_EQ(accelerator.reused().size(), 1u);
  const std::size_t first_columns = accelerator.reused().front().v.size();

  // the next step uses the kept columns from its first update on ...
  std::vector<double> x1(kSize, 0.0), next(kSize);
  accelerator.begin_step();
  EXPECT_EQ(accelerator.next(x1, apply(a, b, x1), 0.1, next), static_cast<int>(first_columns));
  // ... and not once they are dropped: the relaxed update, then this step's columns alone
  accelerator.begin_step();
  accelerator.drop_reused();
  EXPECT_TRUE(accelerator.reused_dropped());
  EXPECT_EQ(accelerator.next(x1, apply(a, b, x1), 0.1, next), 0);
  for (int i = 0; i < kSize; ++i) EXPECT_DOUBLE_EQ(next[i], 0.1 * b[i]);
  x1 = next;
  EXPECT_EQ(accelerator.next(x1, apply(a, b, x1), 0.1, next), 1);
  // the step's end forgets the dropped steps and keeps this one's
  accelerator.end_step();
  ASSERT_EQ(accelerator.reused().size(), 1u);
  EXPECT_EQ(accelerator.reused().front().v.size(), 1u);
  EXPECT_FALSE(accelerator.reused_dropped());
}

TEST(InterfaceQuasiNewton, WithoutColumnsTheUpdateIsRelaxed) {
  InterfaceQuasiNewton accelerator(MPI_COMM_SELF, 0, 10, 1e-12);
  accelerator.begin_step();
  const std::vector<double> x = {1, 2}, x_tilde = {3, 0};
  std::vector<double> next(2);
  EXPECT_EQ(accelerator.next(x, x_tilde, 0.25, next), 0);
  EXPECT_DOUBLE_EQ(next[0], 1.5);
  EXPECT_DOUBLE_EQ(next[1], 1.5);
}

}  // namespace
}  // namespace coapt::coupling
