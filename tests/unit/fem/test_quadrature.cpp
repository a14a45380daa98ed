// Quadrature rules on the reference simplex: exactness on every monomial, weights, points.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/fem/quadrature.hpp"

namespace {

using coapt::fem::QuadratureRule;

double factorial(int n) {
  double f = 1;
  for (int k = 2; k <= n; ++k) f *= k;
  return f;
}

/// ∫ over the reference dim-simplex of x^e0 y^e1 z^e2 = e0! e1! e2! / (e0+e1+e2+dim)!.
double exact_monomial(int dim, const int* e) {
  double numerator = 1;
  int total = 0;
  for (int k = 0; k < dim; ++k) {
    numerator *= factorial(e[k]);
    total += e[k];
  }
  return numerator / factorial(total + dim);
}

double integrate_monomial(const QuadratureRule& rule, const int* e) {
  double sum = 0;
  for (int q = 0; q < rule.size(); ++q) {
    double value = rule.weights[q];
    for (int k = 0; k < rule.dim; ++k) value *= std::pow(rule.point(q)[k], e[k]);
    sum += value;
  }
  return sum;
}

/// Calls f(exponents) for every monomial of total degree <= degree in dim variables.
template <class F>
void for_each_monomial(int dim, int degree, F f) {
  int e[3] = {0, 0, 0};
  for (e[0] = 0; e[0] <= degree; ++e[0])
    for (e[1] = 0; e[1] <= (dim > 1 ? degree - e[0] : 0); ++e[1])
      for (e[2] = 0; e[2] <= (dim > 2 ? degree - e[0] - e[1] : 0); ++e[2]) f(e);
}

std::string name(const QuadratureRule& rule) {
  return std::to_string(rule.dim) + "D degree-" + std::to_string(rule.degree) + " rule with " +
         std::to_string(rule.size()) + " points";
}

/// Every check a rule must pass; `claimed` is the degree it must be exact to.
void check_rule(const QuadratureRule& rule, int dim, int claimed) {
  SCOPED_TRACE(name(rule));
  ASSERT_EQ(rule.dim, dim);
  ASSERT_GE(rule.degree, claimed);
  ASSERT_EQ(rule.points.size(), rule.weights.size() * static_cast<std::size_t>(dim));
  ASSERT_GT(rule.size(), 0);

  double sum = 0;
  for (double w : rule.weights) sum += w;
  EXPECT_NEAR(sum, coapt::fem::reference_simplex_measure(dim), 1e-15);

  // Prefer rules with positive weights and interior points: every rule here has them.
  for (int q = 0; q < rule.size(); ++q) {
    EXPECT_GT(rule.weights[q], 0.0) << "negative or zero weight at point " << q;
    double coordinate_sum = 0;
    for (int k = 0; k < dim; ++k) {
      EXPECT_GT(rule.point(q)[k], 0.0) << "point " << q << " outside (or on the boundary)";
      coordinate_sum += rule.point(q)[k];
    }
    EXPECT_LT(coordinate_sum, 1.0) << "point " << q << " outside (or on the boundary)";
  }

  // Exactness on every monomial up to the rule's own degree, to 1e-13 relative.
  for_each_monomial(dim, rule.degree, [&](const int* e) {
    const double exact = exact_monomial(dim, e);
    const double computed = integrate_monomial(rule, e);
    EXPECT_LE(std::abs(computed - exact), 1e-13 * exact)
        << "monomial exponents (" << e[0] << ", " << e[1] << ", " << e[2] << "): " << computed
        << " instead of " << exact;
  });
}

/// True if some monomial of degree `degree` is integrated wrongly (the rule is not exact there).
bool fails_some_monomial(const QuadratureRule& rule, int degree) {
  bool fails = false;
  for_each_monomial(rule.dim, degree, [&](const int* e) {
    int total = 0;
    for (int k = 0; k < rule.dim; ++k) total += e[k];
    if (total != degree) return;
    const double exact = exact_monomial(rule.dim, e);
    if (std::abs(integrate_monomial(rule, e) - exact) > 1e-10 * exact) fails = true;
  });
  return fails;
}

TEST(SimplexQuadrature, EveryDegreeUpTo10IsExactWithPositiveWeightsInside) {
  for (int dim = 1; dim <= 3; ++dim)
    for (int degree = 0; degree <= 10; ++degree) {
      SCOPED_TRACE("dim " + std::to_string(dim) + " degree " + std::to_string(degree));
      check_rule(coapt::fem::simplex_quadrature(dim, degree), dim, degree);
    }
}

TEST(SimplexQuadrature, HigherDegreesStillExact) {
  for (int dim = 1; dim <= 3; ++dim)
    for (int degree : {11, 12, 15, 20})
      check_rule(coapt::fem::simplex_quadrature(dim, degree), dim, degree);
}

TEST(SimplexQuadrature, TabulatedRulesAreExactToTheirDegreeAndNoMore) {
  int count = 0;
  for (int dim = 2; dim <= 3; ++dim)
    for (const auto& rule : coapt::fem::tabulated_simplex_quadratures(dim)) {
      check_rule(rule, dim, rule.degree);
      EXPECT_TRUE(fails_some_monomial(rule, rule.degree + 1))
          << name(rule) << " is exact one degree higher than it claims";
      ++count;
    }
  EXPECT_EQ(count, 13);
  EXPECT_TRUE(coapt::fem::tabulated_simplex_quadratures(1).empty());
}

TEST(SimplexQuadrature, CollapsedRulesForEveryDegree) {
  for (int dim = 1; dim <= 3; ++dim)
    for (int degree = 0; degree <= 10; ++degree) {
      const QuadratureRule rule = coapt::fem::collapsed_simplex_quadrature(dim, degree);
      const int m = degree / 2 + 1;
      EXPECT_EQ(rule.size(), static_cast<int>(std::pow(m, dim)));
      EXPECT_EQ(rule.degree, 2 * m - 1);
      check_rule(rule, dim, degree);
      EXPECT_TRUE(fails_some_monomial(rule, rule.degree + 1));
    }
}

TEST(SimplexQuadrature, PicksTheCheapestRule) {
  // Expected point counts for degrees 0..10 (tabulated symmetric rules vs m^dim collapsed).
  const int expected[4][11] = {
      {},
      {1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6},             // Gauss-Legendre
      {1, 1, 3, 4, 6, 7, 12, 12, 16, 19, 25},        // 3: collapsed 2×2; else symmetric
      {1, 1, 4, 8, 14, 14, 24, 64, 125, 125, 216}};  // 8, 64, 125, 216: collapsed
  for (int dim = 1; dim <= 3; ++dim)
    for (int degree = 0; degree <= 10; ++degree)
      EXPECT_EQ(coapt::fem::simplex_quadrature(dim, degree).size(), expected[dim][degree])
          << "dim " << dim << " degree " << degree;
  // Informational: what each (dim, degree) maps to.
  for (int dim = 1; dim <= 3; ++dim) {
    std::cout << "[ info     ] " << dim << "D rules (degree: points):";
    for (int degree = 0; degree <= 10; ++degree)
      std::cout << " " << degree << ":" << coapt::fem::simplex_quadrature(dim, degree).size();
    std::cout << "\n";
  }
}

TEST(SimplexQuadrature, CachedReferenceIsStable) {
  const QuadratureRule* first = &coapt::fem::simplex_quadrature(3, 4);
  for (int degree = 0; degree <= 12; ++degree) coapt::fem::simplex_quadrature(2, degree);
  EXPECT_EQ(first, &coapt::fem::simplex_quadrature(3, 4));
}

TEST(SimplexQuadrature, RejectsBadArguments) {
  EXPECT_THROW(coapt::fem::simplex_quadrature(0, 2), coapt::InputError);
  EXPECT_THROW(coapt::fem::simplex_quadrature(4, 2), coapt::InputError);
  EXPECT_THROW(coapt::fem::simplex_quadrature(2, -1), coapt::InputError);
  EXPECT_THROW(coapt::fem::simplex_quadrature(2, coapt::fem::max_quadrature_degree + 1),
               coapt::InputError);
}

TEST(GaussJacobi, KnownRulesAndMoments) {
  std::vector<double> x, w;
  // 2-point Gauss-Legendre on [0, 1]: (1 ∓ 1/√3)/2, weights 1/2.
  coapt::fem::gauss_jacobi(2, 0.0, x, w);
  EXPECT_NEAR(x[0], 0.5 - 0.5 / std::sqrt(3.0), 3e-16);
  EXPECT_NEAR(x[1], 0.5 + 0.5 / std::sqrt(3.0), 3e-16);
  EXPECT_NEAR(w[0], 0.5, 3e-16);
  EXPECT_NEAR(w[1], 0.5, 3e-16);
  // 1 point for (1-u)^alpha: the mean 1/(alpha+2), weight 1/(alpha+1).
  for (double alpha : {0.0, 1.0, 2.0, 0.5}) {
    coapt::fem::gauss_jacobi(1, alpha, x, w);
    EXPECT_NEAR(x[0], 1 / (alpha + 2), 3e-16);
    EXPECT_NEAR(w[0], 1 / (alpha + 1), 3e-16);
  }
  // n points integrate u^k (1-u)^alpha exactly for k <= 2n-1: Beta(k+1, alpha+1).
  for (int alpha = 0; alpha <= 2; ++alpha)
    for (int n = 1; n <= 30; ++n) {
      coapt::fem::gauss_jacobi(n, alpha, x, w);
      for (int i = 1; i < n; ++i) EXPECT_LT(x[i - 1], x[i]);
      for (int k = 0; k <= 2 * n - 1; ++k) {
        double sum = 0;
        for (int i = 0; i < n; ++i) sum += w[i] * std::pow(x[i], k);
        const double exact = std::exp(std::lgamma(k + 1.0) + std::lgamma(alpha + 1.0) -
                                      std::lgamma(k + alpha + 2.0));
        EXPECT_NEAR(sum, exact, 1e-13 * exact) << "n " << n << " alpha " << alpha << " k " << k;
      }
    }
}

}  // namespace
