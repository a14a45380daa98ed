// P1 element kernels against quadrature-built versions, and their structural properties.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "coapt/fem/kernels.hpp"

namespace {

using namespace coapt::fem;

template <int Dim>
using Vertices = Eigen::Matrix<double, Dim + 1, Dim>;
template <int Dim>
constexpr int n_dofs = (Dim + 1) * Dim;
template <int Dim>
using ElasticityMatrix = Eigen::Matrix<double, n_dofs<Dim>, n_dofs<Dim>>;

template <int Dim>
Vertices<Dim> random_simplex(std::mt19937_64& rng, double size = 1.0) {
  std::uniform_real_distribution<double> u(-size, size);
  while (true) {
    Vertices<Dim> v;
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i < Dim; ++i) v(a, i) = u(rng);
    const Eigen::Matrix<double, Dim, Dim> J = (v.bottomRows(Dim).rowwise() - v.row(0)).transpose();
    if (std::abs(J.determinant()) > 0.05 * std::pow(0.5 * size, Dim)) return v;
  }
}

/// Vertex pointers of a simplex (the storage lives in `rows`).
template <int Dim>
struct Pointers {
  explicit Pointers(const Vertices<Dim>& v) {
    for (int a = 0; a <= Dim; ++a) {
      for (int i = 0; i < Dim; ++i) rows[a][i] = v(a, i);
      p[a] = rows[a];
    }
  }
  double rows[Dim + 1][Dim];
  const double* p[Dim + 1];
};

template <class A, class B>
double relative_difference(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
}

// ---- Independent, quadrature-built references -------------------------------------------

/// Gradients from a pivoted-LU inverse of J (not the adjugate the library uses).
template <int Dim>
Eigen::Matrix<double, Dim + 1, Dim> lu_gradients(const Vertices<Dim>& v) {
  const Eigen::MatrixXd J = (v.bottomRows(Dim).rowwise() - v.row(0)).transpose();
  const Eigen::MatrixXd inverse = J.fullPivLu().inverse();
  Eigen::Matrix<double, Dim + 1, Dim> g;
  g.bottomRows(Dim) = inverse;
  g.row(0) = -inverse.colwise().sum();
  return g;
}

template <int Dim>
double lu_jacobian(const Vertices<Dim>& v) {
  const Eigen::MatrixXd J = (v.bottomRows(Dim).rowwise() - v.row(0)).transpose();
  return std::abs(J.fullPivLu().determinant());
}

template <int Dim>
Eigen::Matrix<double, Dim + 1, Dim + 1> quadrature_mass(const Vertices<Dim>& v) {
  const QuadratureRule& rule = simplex_quadrature(Dim, 2);
  Eigen::Matrix<double, Dim + 1, Dim + 1> M = Eigen::Matrix<double, Dim + 1, Dim + 1>::Zero();
  for (int q = 0; q < rule.size(); ++q) {
    const Eigen::Map<const Eigen::Matrix<double, Dim, 1>> xi(rule.point(q));
    const Eigen::Matrix<double, Dim + 1, 1> lambda = p1_values<Dim>(xi);
    M += rule.weights[q] * lu_jacobian<Dim>(v) * lambda * lambda.transpose();
  }
  return M;
}

template <int Dim>
Eigen::Matrix<double, Dim + 1, Dim + 1> quadrature_laplacian(const Vertices<Dim>& v) {
  const QuadratureRule& rule = simplex_quadrature(Dim, 2);
  const auto g = lu_gradients<Dim>(v);
  Eigen::Matrix<double, Dim + 1, Dim + 1> K = Eigen::Matrix<double, Dim + 1, Dim + 1>::Zero();
  for (int q = 0; q < rule.size(); ++q)
    K += rule.weights[q] * lu_jacobian<Dim>(v) * g * g.transpose();
  return K;
}

/// K = Σ_q w_q |J| Bᵀ D B with Voigt strains (engineering shears) and the isotropic D.
template <int Dim>
ElasticityMatrix<Dim> quadrature_elasticity(const Vertices<Dim>& v, double lambda, double mu) {
  constexpr int n_strains = Dim * (Dim + 1) / 2;
  std::array<std::array<int, 2>, n_strains> pairs{};
  int s = 0;
  for (int k = 0; k < Dim; ++k) pairs[s++] = {k, k};
  for (int k = 0; k < Dim; ++k)
    for (int l = k + 1; l < Dim; ++l) pairs[s++] = {k, l};
  Eigen::Matrix<double, n_strains, n_strains> D =
      Eigen::Matrix<double, n_strains, n_strains>::Zero();
  for (int r = 0; r < n_strains; ++r) {
    const bool normal = pairs[r][0] == pairs[r][1];
    for (int c = 0; c < n_strains; ++c)
      if (normal && pairs[c][0] == pairs[c][1]) D(r, c) = lambda;
    D(r, r) += normal ? 2 * mu : mu;
  }
  const auto g = lu_gradients<Dim>(v);
  Eigen::Matrix<double, n_strains, n_dofs<Dim>> B =
      Eigen::Matrix<double, n_strains, n_dofs<Dim>>::Zero();
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i)
      for (int r = 0; r < n_strains; ++r) {
        const int k = pairs[r][0], l = pairs[r][1];  // engineering strain of u = λ_a e_i
        if (k == l) {
          B(r, a * Dim + i) = k == i ? g(a, k) : 0.0;
        } else {
          B(r, a * Dim + i) = (k == i ? g(a, l) : 0.0) + (l == i ? g(a, k) : 0.0);
        }
      }
  const QuadratureRule& rule = simplex_quadrature(Dim, 2);
  ElasticityMatrix<Dim> K = ElasticityMatrix<Dim>::Zero();
  for (int q = 0; q < rule.size(); ++q)
    K += rule.weights[q] * lu_jacobian<Dim>(v) * B.transpose() * D * B;
  return K;
}

// ---- Mass, Laplacian --------------------------------------------------------------------

template <int Dim>
void check_scalar_kernels(std::mt19937_64& rng) {
  for (int trial = 0; trial < 100; ++trial) {
    const double size = std::pow(10.0, trial % 7 - 3);  // 1e-3 .. 1e3
    const Vertices<Dim> v = random_simplex<Dim>(rng, size);
    const P1Geometry<Dim> g = p1_geometry(v);

    const auto M = element_mass(g);
    EXPECT_LE(relative_difference(M, quadrature_mass<Dim>(v)), 1e-12);
    EXPECT_NEAR(M.sum(), g.measure, 1e-14 * g.measure);
    const auto lumped = element_lumped_mass(g);
    EXPECT_LE(relative_difference(lumped, M.rowwise().sum()), 1e-14);
    EXPECT_NEAR(lumped.sum(), g.measure, 1e-14 * g.measure);

    const auto K = element_laplacian(g);
    const double scale = K.cwiseAbs().maxCoeff();
    EXPECT_LE(relative_difference(K, quadrature_laplacian<Dim>(v)), 1e-12);
    EXPECT_LE(K.rowwise().sum().cwiseAbs().maxCoeff(), 1e-13 * scale);
    EXPECT_LE((K - K.transpose()).cwiseAbs().maxCoeff(), 0.0);

    // Fast path from pointers: same matrix, signed measure returned.
    Pointers<Dim> p(v);
    Eigen::Matrix<double, Dim + 1, Dim + 1> fast;
    const double signed_measure = element_laplacian<Dim>(p.p, fast.data());
    EXPECT_DOUBLE_EQ(signed_measure, g.signed_measure);
    EXPECT_LE(relative_difference(fast, K), 1e-13);
    EXPECT_LE(fast.rowwise().sum().cwiseAbs().maxCoeff(), 1e-13 * scale);
  }
}

TEST(ElementKernels, MassAndLaplacianMatchQuadrature) {
  std::mt19937_64 rng(2024);
  check_scalar_kernels<1>(rng);
  check_scalar_kernels<2>(rng);
  check_scalar_kernels<3>(rng);
}

TEST(ElementKernels, LaplacianOfReferenceTriangleAndTetrahedron) {
  Vertices<2> triangle;
  triangle << 0, 0, 1, 0, 0, 1;
  Eigen::Matrix3d expected2;
  expected2 << 1, -0.5, -0.5, -0.5, 0.5, 0, -0.5, 0, 0.5;
  EXPECT_LE(relative_difference(element_laplacian(p1_geometry(triangle)), expected2), 1e-15);
  Vertices<3> tet;
  tet << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Eigen::Matrix4d expected3;
  expected3 << 3, -1, -1, -1, -1, 1, 0, 0, -1, 0, 1, 0, -1, 0, 0, 1;
  expected3 /= 6;
  EXPECT_LE(relative_difference(element_laplacian(p1_geometry(tet)), expected3), 1e-15);
}

// ---- Elasticity -------------------------------------------------------------------------

/// Rigid-body modes (columns): Dim translations, Dim(Dim-1)/2 rotations about the origin.
template <int Dim>
Eigen::Matrix<double, n_dofs<Dim>, Eigen::Dynamic> rigid_modes(const Vertices<Dim>& v) {
  const int n_modes = Dim * (Dim + 1) / 2;
  Eigen::Matrix<double, n_dofs<Dim>, Eigen::Dynamic> R(n_dofs<Dim>, n_modes);
  R.setZero();
  int m = 0;
  for (int i = 0; i < Dim; ++i, ++m)
    for (int a = 0; a <= Dim; ++a) R(a * Dim + i, m) = 1;
  for (int k = 0; k < Dim; ++k)
    for (int l = k + 1; l < Dim; ++l, ++m)
      for (int a = 0; a <= Dim; ++a) {  // u = x_k e_l − x_l e_k
        R(a * Dim + l, m) = v(a, k);
        R(a * Dim + k, m) = -v(a, l);
      }
  return R;
}

template <int Dim>
void check_elasticity(std::mt19937_64& rng) {
  const int n_rigid = Dim * (Dim + 1) / 2;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    const double size = std::pow(10.0, trial % 5 - 2);
    const Vertices<Dim> v = random_simplex<Dim>(rng, size);
    const P1Geometry<Dim> g = p1_geometry(v);
    // Steel-like and nearly incompressible materials.
    const double E = 200e9, nu = trial % 2 ? 0.3 : 0.499;
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));

    const ElasticityMatrix<Dim> K = element_elasticity(g, lambda, mu);
    const double scale = K.cwiseAbs().maxCoeff();
    EXPECT_LE(relative_difference(K, quadrature_elasticity<Dim>(v, lambda, mu)), 1e-12);
    EXPECT_LE((K - K.transpose()).cwiseAbs().maxCoeff(), 0.0);

    ElasticityMatrix<Dim> fast;
    Pointers<Dim> p(v);
    EXPECT_DOUBLE_EQ(element_elasticity<Dim>(p.p, lambda, mu, fast.data()), g.signed_measure);
    EXPECT_LE(relative_difference(fast, K), 1e-13);

    // Rigid-body modes are in the kernel ...
    const auto R = rigid_modes<Dim>(v);
    for (int m = 0; m < n_rigid; ++m)
      EXPECT_LE((K * R.col(m)).cwiseAbs().maxCoeff(),
                1e-12 * scale * R.col(m).cwiseAbs().maxCoeff())
          << "rigid mode " << m;
    // ... and are the whole kernel: positive semi-definite with exactly n_rigid zero eigenvalues.
    Eigen::SelfAdjointEigenSolver<ElasticityMatrix<Dim>> eigen(K);
    const auto& values = eigen.eigenvalues();  // ascending
    const double largest = values(n_dofs<Dim> - 1);
    for (int k = 0; k < n_rigid; ++k)
      EXPECT_LE(std::abs(values(k)), 1e-12 * largest) << "eigenvalue " << k;
    for (int k = n_rigid; k < n_dofs<Dim>; ++k)
      EXPECT_GT(values(k), 1e-8 * largest) << "eigenvalue " << k;

    // Energy of a linear displacement u = A x + c: uᵀKu = 2 · |T| (λ tr(ε)² + 2μ ε:ε)/2.
    Eigen::Matrix<double, Dim, Dim> A;
    Eigen::Matrix<double, Dim, 1> c;
    for (int i = 0; i < Dim; ++i) {
      c(i) = u(rng);
      for (int j = 0; j < Dim; ++j) A(i, j) = u(rng);
    }
    Eigen::Matrix<double, n_dofs<Dim>, 1> displacement;
    for (int a = 0; a <= Dim; ++a)
      displacement.template segment<Dim>(a * Dim) = A * v.row(a).transpose() + c;
    const Eigen::Matrix<double, Dim, Dim> strain = 0.5 * (A + A.transpose());
    const double energy =
        0.5 * g.measure *
        (lambda * strain.trace() * strain.trace() + 2 * mu * strain.squaredNorm());
    // uᵀKu cancels (rigid parts of u, λ ≫ μ): the attainable accuracy is relative to |u|ᵀ|K||u|.
    const double magnitude = displacement.cwiseAbs().dot(K.cwiseAbs() * displacement.cwiseAbs());
    EXPECT_NEAR(displacement.dot(K * displacement), 2 * energy, 1e-13 * magnitude);
    // Without translation, for a pure stretch A = diag: no cancellation, 1e-12 relative.
    Eigen::Matrix<double, n_dofs<Dim>, 1> stretch;
    const Eigen::Matrix<double, Dim, 1> factors = A.diagonal().cwiseAbs();
    for (int a = 0; a <= Dim; ++a)
      stretch.template segment<Dim>(a * Dim) = factors.cwiseProduct(v.row(a).transpose());
    const double stretch_energy =
        0.5 * g.measure * (lambda * factors.sum() * factors.sum() + 2 * mu * factors.squaredNorm());
    EXPECT_NEAR(stretch.dot(K * stretch), 2 * stretch_energy, 1e-12 * 2 * stretch_energy);
  }
}

TEST(ElementKernels, ElasticityMatchesQuadratureAndHasRigidKernel) {
  std::mt19937_64 rng(31415);
  check_elasticity<1>(rng);
  check_elasticity<2>(rng);
  check_elasticity<3>(rng);
}

// ---- Load vector ------------------------------------------------------------------------

template <int Dim>
void check_load(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vertices<Dim> v = random_simplex<Dim>(rng);
    const P1Geometry<Dim> g = p1_geometry(v);
    // f = 1 and f = Σ f_b λ_b (P1): ∫ f λ_a = |T|/(d+1) and (M f)_a, with 2 components.
    const QuadratureRule& rule = simplex_quadrature(Dim, 2);
    Eigen::Matrix<double, Dim + 1, 1> nodal;
    for (int b = 0; b <= Dim; ++b) nodal(b) = u(rng);
    Eigen::MatrixXd values(rule.size(), 2);
    for (int q = 0; q < rule.size(); ++q) {
      const Eigen::Map<const Eigen::Matrix<double, Dim, 1>> xi(rule.point(q));
      values(q, 0) = 1.0;
      values(q, 1) = p1_values<Dim>(xi).dot(nodal);
    }
    const auto load = element_load(g, rule, values);
    ASSERT_EQ(load.cols(), 2);
    EXPECT_LE(relative_difference(load.col(0), element_lumped_mass(g)), 1e-14);
    EXPECT_LE(relative_difference(load.col(1), element_mass(g) * nodal), 1e-13);

    // f a cubic of the physical point: a degree-4 rule is exact, and agrees with degree 10.
    auto f = [](const Eigen::Matrix<double, 1, Dim>& x) {
      double value = 1.0;
      for (int i = 0; i < Dim; ++i) value += (i + 1) * x(i) * x(i) * x(i) - x(i) * x(0);
      return value;
    };
    Eigen::Matrix<double, Dim + 1, 1> results[2];
    int r = 0;
    for (int degree : {4, 10}) {
      const QuadratureRule& exact_rule = simplex_quadrature(Dim, degree);
      const auto x = quadrature_points<Dim>(v, exact_rule);
      Eigen::VectorXd fx(exact_rule.size());
      for (int q = 0; q < exact_rule.size(); ++q) fx(q) = f(x.row(q));
      results[r++] = element_load(g, exact_rule, fx);
    }
    EXPECT_LE(relative_difference(results[0], results[1]), 1e-13);
  }
}

TEST(ElementKernels, LoadVector) {
  std::mt19937_64 rng(4242);
  check_load<1>(rng);
  check_load<2>(rng);
  check_load<3>(rng);
}

TEST(ElementKernels, QuadraturePointsAreMappedPoints) {
  Vertices<2> v;
  v << 1, 1, 3, 1, 1, 2;
  const QuadratureRule& rule = simplex_quadrature(2, 2);
  const auto x = quadrature_points<2>(v, rule);
  for (int q = 0; q < rule.size(); ++q) {
    EXPECT_DOUBLE_EQ(x(q, 0), 1 + 2 * rule.point(q)[0]);
    EXPECT_DOUBLE_EQ(x(q, 1), 1 + rule.point(q)[1]);
  }
}

// ---- Informational timing (never an assertion) -------------------------------------------

/// A structured n³-cube mesh of the unit cube, 6 Kuhn tetrahedra per cube.
void kuhn_mesh(int n, std::vector<double>& coordinates, std::vector<int>& cells) {
  const int np = n + 1;
  coordinates.clear();
  cells.clear();
  for (int k = 0; k < np; ++k)
    for (int j = 0; j < np; ++j)
      for (int i = 0; i < np; ++i) {
        coordinates.push_back(double(i) / n);
        coordinates.push_back(double(j) / n);
        coordinates.push_back(double(k) / n);
      }
  const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& perm : permutations) {
          int corner[3] = {i, j, k};
          cells.push_back((corner[2] * np + corner[1]) * np + corner[0]);
          for (int step = 0; step < 3; ++step) {
            ++corner[perm[step]];
            cells.push_back((corner[2] * np + corner[1]) * np + corner[0]);
          }
        }
}

template <class Kernel>
double tets_per_second(const std::vector<double>& coordinates, const std::vector<int>& cells,
                       Kernel kernel, double& checksum) {
  const std::size_t n_cells = cells.size() / 4;
  double best = 1e30;
  for (int repeat = 0; repeat < 3; ++repeat) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t c = 0; c < n_cells; ++c) {
      const double* p[4];
      for (int a = 0; a < 4; ++a)
        p[a] = coordinates.data() + 3 * static_cast<std::size_t>(cells[4 * c + a]);
      checksum += kernel(p);
    }
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return n_cells / best;
}

TEST(ElementKernels, TimingInformational) {
  std::vector<double> coordinates;
  std::vector<int> cells;
  kuhn_mesh(48, coordinates, cells);
  double checksum = 0;
  const double fast = tets_per_second(
      coordinates, cells,
      [](const double* const* p) {
        double K[16];
        element_laplacian<3>(p, K);
        return K[0] + K[5] + K[10] + K[15];
      },
      checksum);
  const double geometry = tets_per_second(
      coordinates, cells,
      [](const double* const* p) {
        const auto K = element_laplacian(p1_geometry<3>(p));
        return K.trace();
      },
      checksum);
  const double elasticity = tets_per_second(
      coordinates, cells,
      [](const double* const* p) {
        double K[144];
        element_elasticity<3>(p, 1.0, 1.0, K);
        return K[0] + K[143];
      },
      checksum);
  // Every Kuhn tet of the unit cube has trace(K) = ... > 0: the checksum only defeats dead-code
  // removal.
  EXPECT_GT(checksum, 0.0);
  std::cout << "[ info     ] " << cells.size() / 4 << " tets, 3D P1 kernels (M tets/s, one core): "
            << "Laplacian fast path " << fast / 1e6 << ", Laplacian via P1Geometry "
            << geometry / 1e6 << ", elasticity fast path " << elasticity / 1e6 << "\n";
}

}  // namespace
