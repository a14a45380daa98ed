#pragma once
// Shared helpers of the intersection tests: random simplices, rigid motions, structured
// simplex grids (2D: squares cut by a diagonal; 3D: Kuhn subdivision of cubes).

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "coapt/transfer/geometry.hpp"

namespace coapt::transfer::testing {

template <int dim>
using Vertices = std::array<Point<dim>, dim + 1>;

/// Element mass matrix on T: |T| (1 + δ_ij) / ((d + 1)(d + 2)).
template <int dim>
NodalMatrix<dim> element_mass(double measure) {
  NodalMatrix<dim> m;
  for (int i = 0; i <= dim; ++i)
    for (int j = 0; j <= dim; ++j)
      m[i][j] = measure * (i == j ? 2.0 : 1.0) / ((dim + 1) * (dim + 2));
  return m;
}

/// A random simplex with vertices in [lo, hi]^dim whose measure is at least `min_quality`
/// times that of a regular simplex of the same longest edge (rejection sampling).
template <int dim>
Vertices<dim> random_simplex(std::mt19937_64& rng, double lo, double hi,
                             double min_quality = 0.05) {
  std::uniform_real_distribution<double> u(lo, hi);
  while (true) {
    Vertices<dim> v;
    for (auto& p : v)
      for (double& c : p) c = u(rng);
    const Simplex<dim> s = make_simplex<dim>(v);
    double longest = 0.0;
    for (int i = 0; i <= dim; ++i)
      for (int j = i + 1; j <= dim; ++j) {
        double l2 = 0.0;
        for (int k = 0; k < dim; ++k) l2 += (v[i][k] - v[j][k]) * (v[i][k] - v[j][k]);
        longest = std::max(longest, std::sqrt(l2));
      }
    const double regular = dim == 2 ? std::sqrt(3.0) / 4.0 * longest * longest
                                    : longest * longest * longest / (6.0 * std::sqrt(2.0));
    if (s.measure >= min_quality * regular) return v;
  }
}

/// A random rotation (from a normalized random quaternion in 3D, a random angle in 2D).
template <int dim>
std::array<Point<dim>, dim> random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  if constexpr (dim == 2) {
    const double t = std::atan2(g(rng), g(rng));
    return {Point<2>{std::cos(t), -std::sin(t)}, Point<2>{std::sin(t), std::cos(t)}};
  } else {
    double w = g(rng), x = g(rng), y = g(rng), z = g(rng);
    const double n = std::sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    return {Point<3>{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
            Point<3>{2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
            Point<3>{2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  }
}

template <int dim>
Vertices<dim> transform(const Vertices<dim>& v, const std::array<Point<dim>, dim>& rotation,
                        const Point<dim>& shift) {
  Vertices<dim> r;
  for (int p = 0; p <= dim; ++p)
    for (int i = 0; i < dim; ++i) {
      r[p][i] = shift[i];
      for (int j = 0; j < dim; ++j) r[p][i] += rotation[i][j] * v[p][j];
    }
  return r;
}

/// A conforming simplex grid of [0, 1]^dim with n cells per direction; interior nodes moved
/// by up to `jitter` · h per coordinate (keeps every cell valid for jitter ≤ 0.1).
template <int dim>
std::vector<Vertices<dim>> structured_grid(int n, double jitter = 0.0, unsigned seed = 1) {
  const double h = 1.0 / n;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-jitter * h, jitter * h);
  const int m = n + 1;
  std::vector<Point<dim>> nodes;
  const auto index = [m](const std::array<int, dim>& i) {
    int r = 0;
    for (int k = dim - 1; k >= 0; --k) r = r * m + i[k];
    return r;
  };
  const int n_nodes = dim == 2 ? m * m : m * m * m;
  nodes.resize(n_nodes);
  for (int node = 0; node < n_nodes; ++node) {
    std::array<int, dim> i;
    int rest = node;
    bool interior = true;
    for (int k = 0; k < dim; ++k) {
      i[k] = rest % m;
      rest /= m;
      interior = interior && i[k] > 0 && i[k] < n;
    }
    for (int k = 0; k < dim; ++k) nodes[index(i)][k] = i[k] * h + (interior ? u(rng) : 0.0);
  }
  std::vector<Vertices<dim>> cells;
  if constexpr (dim == 2) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Point<2> p00 = nodes[index({i, j})], p10 = nodes[index({i + 1, j})],
                       p01 = nodes[index({i, j + 1})], p11 = nodes[index({i + 1, j + 1})];
        cells.push_back({p00, p10, p11});
        cells.push_back({p00, p11, p01});
      }
  } else {
    // Kuhn: for each permutation π, the path 000 → +e_π0 → +e_π1 → +e_π2 = 111.
    const std::array<std::array<int, 3>, 6> permutations{
        {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          for (const auto& p : permutations) {
            std::array<int, 3> c{i, j, k};
            Vertices<3> cell;
            cell[0] = nodes[index(c)];
            for (int s = 0; s < 3; ++s) {
              ++c[p[s]];
              cell[s + 1] = nodes[index(c)];
            }
            cells.push_back(cell);
          }
  }
  return cells;
}

/// |x − y| ≤ rel · scale, with a readable failure message.
inline ::testing::AssertionResult near_relative(double x, double y, double rel, double scale) {
  if (std::isfinite(x) && std::isfinite(y) && std::fabs(x - y) <= rel * scale)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << x << " vs " << y << ": difference " << std::fabs(x - y)
                                       << " > " << rel << " · " << scale;
}

}  // namespace coapt::transfer::testing
