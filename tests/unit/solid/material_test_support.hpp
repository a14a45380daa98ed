#pragma once
// Helpers shared by the constitutive-law tests: random deformations and rotations,
// central finite differences of ψ and P, and a scalar root finder.

#include <Eigen/Geometry>
#include <functional>
#include <random>

#include "coapt/solid/materials.hpp"

namespace coapt::solid::testing {

/// F = I + scale·R with R uniform in [−1, 1]³ˣ³, redrawn until det F > 0.5.
inline Matrix3 random_deformation(std::mt19937& rng, double scale = 0.25) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (;;) {
    Matrix3 F = Matrix3::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) F(i, j) += scale * uniform(rng);
    if (F.determinant() > 0.5) return F;
  }
}

/// A uniformly random rotation (normalised Gaussian quaternion).
inline Matrix3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// ∂ψ/∂F by central differences with step h.
template <int N>
Eigen::Matrix<double, N, N> finite_difference_gradient(
    const std::function<double(const Eigen::Matrix<double, N, N>&)>& psi,
    const Eigen::Matrix<double, N, N>& F, double h = 1e-6) {
  Eigen::Matrix<double, N, N> gradient;
  for (int k = 0; k < N; ++k)
    for (int L = 0; L < N; ++L) {
      Eigen::Matrix<double, N, N> plus = F, minus = F;
      plus(k, L) += h;
      minus(k, L) -= h;
      gradient(k, L) = (psi(plus) - psi(minus)) / (2.0 * h);
    }
  return gradient;
}

/// ∂P/∂F by central differences with step h, as the N²×N² matrix
/// (row N·i + J, column N·k + L).
template <int N>
Eigen::Matrix<double, N * N, N * N> finite_difference_tangent(
    const std::function<Eigen::Matrix<double, N, N>(const Eigen::Matrix<double, N, N>&)>& P,
    const Eigen::Matrix<double, N, N>& F, double h = 1e-6) {
  Eigen::Matrix<double, N * N, N * N> A;
  for (int k = 0; k < N; ++k)
    for (int L = 0; L < N; ++L) {
      Eigen::Matrix<double, N, N> plus = F, minus = F;
      plus(k, L) += h;
      minus(k, L) -= h;
      const Eigen::Matrix<double, N, N> column = (P(plus) - P(minus)) / (2.0 * h);
      for (int i = 0; i < N; ++i)
        for (int J = 0; J < N; ++J) A(N * i + J, N * k + L) = column(i, J);
    }
  return A;
}

/// The root of a continuous f with a sign change on [low, high], by bisection to round-off.
inline double bisect(const std::function<double(double)>& f, double low, double high) {
  double f_low = f(low);
  for (int iteration = 0; iteration < 200 && high - low > 1e-15 * std::abs(high); ++iteration) {
    const double middle = 0.5 * (low + high);
    const double f_middle = f(middle);
    if ((f_middle > 0.0) == (f_low > 0.0)) {
      low = middle;
      f_low = f_middle;
    } else {
      high = middle;
    }
  }
  return 0.5 * (low + high);
}

/// Relative difference ‖a − b‖ / ‖b‖ (Frobenius).
template <class A, class B>
double relative_difference(const A& a, const B& b) {
  return (a - b).norm() / b.norm();
}

}  // namespace coapt::solid::testing
