#pragma once
// Reference geometry for the intersection tests, sharing no code with the clipping kernels:
// A ∩ B by vertex enumeration of the half-space system (every d-tuple of face planes
// solved by Cramer's rule, points kept if they satisfy all constraints), faces rebuilt by
// sorting the points on each plane by angle, cut into simplices coned to the mean point.
// Integrals on those simplices use the exact formula
//   ∫_T λ_0^a0 ... λ_d^ad = d! |T| a0! ... ad! / (d + a0 + ... + ad)!.
// Slow (allocates, O(planes^d)) and meant for configurations in general position.

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "coapt/transfer/geometry.hpp"

namespace coapt::transfer::reference {

template <int dim>
using Vertices = std::array<Point<dim>, dim + 1>;

inline double factorial(int n) {
  double f = 1.0;
  for (int k = 2; k <= n; ++k) f *= k;
  return f;
}

/// |T| of a simplex, computed by Gaussian elimination (no cofactor formulas).
template <int dim>
double simplex_measure(const Vertices<dim>& v) {
  std::array<std::array<double, dim>, dim> m;
  for (int r = 0; r < dim; ++r)
    for (int c = 0; c < dim; ++c) m[r][c] = v[r + 1][c] - v[0][c];
  double det = 1.0;
  for (int c = 0; c < dim; ++c) {
    int pivot = c;
    for (int r = c + 1; r < dim; ++r)
      if (std::fabs(m[r][c]) > std::fabs(m[pivot][c])) pivot = r;
    if (m[pivot][c] == 0.0) return 0.0;
    if (pivot != c) {
      std::swap(m[pivot], m[c]);
      det = -det;
    }
    det *= m[c][c];
    for (int r = c + 1; r < dim; ++r) {
      const double f = m[r][c] / m[c][c];
      for (int k = c; k < dim; ++k) m[r][k] -= f * m[c][k];
    }
  }
  return std::fabs(det) / factorial(dim);
}

/// Barycentric coordinates of x in simplex v, by solving [v_0..v_d; 1..1] λ = [x; 1].
template <int dim>
std::array<double, dim + 1> barycentric(const Vertices<dim>& v, const Point<dim>& x) {
  constexpr int n = dim + 1;
  std::array<std::array<double, n + 1>, n> m;
  for (int r = 0; r < dim; ++r) {
    for (int c = 0; c < n; ++c) m[r][c] = v[c][r];
    m[r][n] = x[r];
  }
  for (int c = 0; c < n; ++c) m[dim][c] = 1.0;
  m[dim][n] = 1.0;
  for (int c = 0; c < n; ++c) {
    int pivot = c;
    for (int r = c + 1; r < n; ++r)
      if (std::fabs(m[r][c]) > std::fabs(m[pivot][c])) pivot = r;
    std::swap(m[pivot], m[c]);
    for (int r = 0; r < n; ++r) {
      if (r == c) continue;
      const double f = m[r][c] / m[c][c];
      for (int k = c; k <= n; ++k) m[r][k] -= f * m[c][k];
    }
  }
  std::array<double, n> lambda;
  for (int r = 0; r < n; ++r) lambda[r] = m[r][n] / m[r][r];
  return lambda;
}

/// ∫_T Π_k λ_k^{a_k} (exact).
template <int dim>
double lambda_monomial_integral(double measure, const std::array<int, dim + 1>& exponents) {
  int total = 0;
  double numerator = factorial(dim) * measure;
  for (int a : exponents) {
    total += a;
    numerator *= factorial(a);
  }
  return numerator / factorial(dim + total);
}

/// ∫_T f g for affine f, g given by their vertex values (exact).
template <int dim>
double affine_product_integral(double measure, const std::array<double, dim + 1>& f,
                               const std::array<double, dim + 1>& g) {
  double result = 0.0;
  for (int k = 0; k <= dim; ++k)
    for (int l = 0; l <= dim; ++l) {
      std::array<int, dim + 1> exponents{};
      exponents[k] += 1;
      exponents[l] += 1;
      result += f[k] * g[l] * lambda_monomial_integral<dim>(measure, exponents);
    }
  return result;
}

/// ∫_T x^α for a monomial of total degree ≤ 2 (α = powers per coordinate), exact: x_c is
/// the affine function with vertex values v_k[c].
template <int dim>
double monomial_integral(const Vertices<dim>& v, const std::array<int, dim>& alpha) {
  const double measure = simplex_measure<dim>(v);
  std::array<int, 2> coordinates{};
  int degree = 0;
  for (int c = 0; c < dim; ++c)
    for (int p = 0; p < alpha[c]; ++p) coordinates[degree++] = c;
  const auto values = [&](int c) {
    std::array<double, dim + 1> f;
    for (int k = 0; k <= dim; ++k) f[k] = v[k][c];
    return f;
  };
  if (degree == 0) return measure;
  if (degree == 1) {
    double sum = 0.0;
    for (int k = 0; k <= dim; ++k) {
      std::array<int, dim + 1> e{};
      e[k] = 1;
      sum += v[k][coordinates[0]] * lambda_monomial_integral<dim>(measure, e);
    }
    return sum;
  }
  return affine_product_integral<dim>(measure, values(coordinates[0]), values(coordinates[1]));
}

/// A ∩ B as a list of simplices (empty when the intersection has no interior).
template <int dim>
std::vector<Vertices<dim>> intersection(const Vertices<dim>& a, const Vertices<dim>& b) {
  struct Plane {
    Point<dim> normal;  // unit, outward
    double offset;      // inside: normal · x ≤ offset
  };
  std::vector<Plane> planes;
  double scale = 0.0;
  for (const Vertices<dim>* s : {&a, &b})
    for (const auto& p : *s)
      for (int k = 0; k < dim; ++k) scale = std::max(scale, std::fabs(p[k]));
  scale = std::max(scale, 1e-300);
  for (const Vertices<dim>* s : {&a, &b})
    for (int i = 0; i <= dim; ++i) {
      std::array<Point<dim>, dim> face;
      for (int k = 0, f = 0; k <= dim; ++k)
        if (k != i) face[f++] = (*s)[k];
      Point<dim> n;
      if constexpr (dim == 2) {
        n = {face[1][1] - face[0][1], face[0][0] - face[1][0]};
      } else {
        Point<3> u, w;
        for (int k = 0; k < 3; ++k) {
          u[k] = face[1][k] - face[0][k];
          w[k] = face[2][k] - face[0][k];
        }
        n = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      }
      double length = 0.0;
      for (double c : n) length += c * c;
      length = std::sqrt(length);
      for (double& c : n) c /= length;
      double offset = 0.0, opposite = 0.0;
      for (int k = 0; k < dim; ++k) {
        offset += n[k] * face[0][k];
        opposite += n[k] * (*s)[i][k];
      }
      if (opposite > offset) {
        for (double& c : n) c = -c;
        offset = -offset;
      }
      planes.push_back({n, offset});
    }
  const double tol = 1e-10 * scale;
  std::vector<Point<dim>> points;
  const int n_planes = static_cast<int>(planes.size());
  const auto try_point = [&](const std::array<int, dim>& chosen) {
    // Cramer's rule on the dim × dim system normal_c · x = offset_c
    std::array<std::array<double, dim>, dim> m;
    std::array<double, dim> rhs;
    for (int r = 0; r < dim; ++r) {
      m[r] = planes[chosen[r]].normal;
      rhs[r] = planes[chosen[r]].offset;
    }
    const auto det = [](const std::array<std::array<double, dim>, dim>& q) {
      if constexpr (dim == 2)
        return q[0][0] * q[1][1] - q[0][1] * q[1][0];
      else
        return q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) -
               q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
               q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0]);
    };
    const double d = det(m);
    if (std::fabs(d) < 1e-9) return;
    Point<dim> x;
    for (int c = 0; c < dim; ++c) {
      auto mc = m;
      for (int r = 0; r < dim; ++r) mc[r][c] = rhs[r];
      x[c] = det(mc) / d;
    }
    for (const Plane& p : planes) {
      double value = -p.offset;
      for (int k = 0; k < dim; ++k) value += p.normal[k] * x[k];
      if (value > tol) return;
    }
    for (const auto& y : points) {
      double distance = 0.0;
      for (int k = 0; k < dim; ++k) distance = std::max(distance, std::fabs(x[k] - y[k]));
      if (distance < 1e2 * tol) return;
    }
    points.push_back(x);
  };
  if constexpr (dim == 2) {
    for (int i = 0; i < n_planes; ++i)
      for (int j = i + 1; j < n_planes; ++j) try_point({i, j});
  } else {
    for (int i = 0; i < n_planes; ++i)
      for (int j = i + 1; j < n_planes; ++j)
        for (int k = j + 1; k < n_planes; ++k) try_point({i, j, k});
  }
  std::vector<Vertices<dim>> simplices;
  if (static_cast<int>(points.size()) < dim + 1) return simplices;
  Point<dim> center{};
  for (const auto& p : points)
    for (int k = 0; k < dim; ++k) center[k] += p[k] / points.size();

  if constexpr (dim == 2) {
    std::sort(points.begin(), points.end(), [&](const Point<2>& p, const Point<2>& q) {
      return std::atan2(p[1] - center[1], p[0] - center[0]) <
             std::atan2(q[1] - center[1], q[0] - center[0]);
    });
    for (std::size_t k = 0; k < points.size(); ++k)
      simplices.push_back({center, points[k], points[(k + 1) % points.size()]});
  } else {
    for (const Plane& p : planes) {
      std::vector<Point<3>> face;
      for (const auto& x : points) {
        double value = -p.offset;
        for (int k = 0; k < 3; ++k) value += p.normal[k] * x[k];
        if (std::fabs(value) <= 1e2 * tol) face.push_back(x);
      }
      if (face.size() < 3) continue;
      Point<3> fc{};
      for (const auto& x : face)
        for (int k = 0; k < 3; ++k) fc[k] += x[k] / face.size();
      Point<3> u{face[0][0] - fc[0], face[0][1] - fc[1], face[0][2] - fc[2]};
      double length = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (double& c : u) c /= length;
      const Point<3>& n = p.normal;
      const Point<3> w{n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2],
                       n[0] * u[1] - n[1] * u[0]};
      const auto angle = [&](const Point<3>& x) {
        double pu = 0.0, pw = 0.0;
        for (int k = 0; k < 3; ++k) {
          pu += u[k] * (x[k] - fc[k]);
          pw += w[k] * (x[k] - fc[k]);
        }
        return std::atan2(pw, pu);
      };
      std::sort(face.begin(), face.end(),
                [&](const Point<3>& x, const Point<3>& y) { return angle(x) < angle(y); });
      for (std::size_t k = 1; k + 1 < face.size(); ++k)
        simplices.push_back({center, face[0], face[k], face[k + 1]});
    }
  }
  return simplices;
}

/// Sums f(simplex) over a decomposition.
template <int dim, class F>
double sum_over(const std::vector<Vertices<dim>>& simplices, F&& f) {
  double total = 0.0;
  for (const auto& s : simplices) total += f(s);
  return total;
}

/// ∫ λ^A_i λ^B_j over the union of `simplices` (exact, by the λ-monomial formula).
template <int dim>
NodalMatrix<dim> mass(const std::vector<Vertices<dim>>& simplices, const Vertices<dim>& a,
                      const Vertices<dim>& b) {
  NodalMatrix<dim> m{};
  for (const auto& s : simplices) {
    const double measure = simplex_measure<dim>(s);
    std::array<std::array<double, dim + 1>, dim + 1> la, lb;  // [basis][vertex of s]
    for (int k = 0; k <= dim; ++k) {
      const auto x = barycentric<dim>(a, s[k]);
      const auto y = barycentric<dim>(b, s[k]);
      for (int i = 0; i <= dim; ++i) {
        la[i][k] = x[i];
        lb[i][k] = y[i];
      }
    }
    for (int i = 0; i <= dim; ++i)
      for (int j = 0; j <= dim; ++j) m[i][j] += affine_product_integral<dim>(measure, la[i], lb[j]);
  }
  return m;
}

}  // namespace coapt::transfer::reference
