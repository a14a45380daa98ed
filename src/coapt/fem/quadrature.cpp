#include "coapt/fem/quadrature.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <string>
#include <utility>

#include "coapt/core/error.hpp"

namespace coapt::fem {

namespace {

// ---------------------------------------------------------------------------------------
// Tabulated symmetric rules, given by orbits of barycentric coordinates (λ_0, ..., λ_dim);
// the reference point is (λ_1, ..., λ_dim). Weights are per point, on the reference simplex
// (summing to 1/2 in 2D, 1/6 in 3D).
// ---------------------------------------------------------------------------------------

enum class Orbit {
  S3,    // 2D centroid
  S21,   // 2D (a, a, 1-2a): 3 points
  S111,  // 2D (a, b, 1-a-b): 6 points
  C3,    // 2D cyclic permutations of (a, b, 1-a-b): 3 points
  S4,    // 3D centroid
  S31,   // 3D (a, a, a, 1-3a): 4 points
  S22,   // 3D (a, a, 1/2-a, 1/2-a): 6 points
  S211,  // 3D (a, a, b, 1-2a-b): 12 points
};

struct OrbitData {
  Orbit kind;
  double a = 0, b = 0;  // parameters (unused ones 0)
  double w = 0;         // weight of each point of the orbit
};

struct TabulatedRule {
  int dim;
  int degree;
  std::vector<OrbitData> orbits;
};

// Appends the distinct permutations of `labels` (a multiset of indices into `values`) as
// barycentric points. Permutations are distinct by label, not by value, so an orbit never
// loses points because two parameters happen to coincide numerically.
void append_permutations(std::vector<int> labels, const std::vector<double>& values, double w,
                         QuadratureRule& rule) {
  std::sort(labels.begin(), labels.end());
  do {
    for (std::size_t k = 1; k < labels.size(); ++k) rule.points.push_back(values[labels[k]]);
    rule.weights.push_back(w);
  } while (std::next_permutation(labels.begin(), labels.end()));
}

QuadratureRule expand(const TabulatedRule& table) {
  QuadratureRule rule;
  rule.dim = table.dim;
  rule.degree = table.degree;
  for (const auto& o : table.orbits) {
    const double a = o.a, b = o.b;
    switch (o.kind) {
      case Orbit::S3:
        append_permutations({0, 0, 0}, {1.0 / 3.0}, o.w, rule);
        break;
      case Orbit::S21:
        append_permutations({0, 0, 1}, {a, 1 - 2 * a}, o.w, rule);
        break;
      case Orbit::S111:
        append_permutations({0, 1, 2}, {a, b, 1 - a - b}, o.w, rule);
        break;
      case Orbit::C3: {
        const double l[3] = {a, b, 1 - a - b};
        for (int r = 0; r < 3; ++r) {
          rule.points.push_back(l[(r + 1) % 3]);
          rule.points.push_back(l[(r + 2) % 3]);
          rule.weights.push_back(o.w);
        }
        break;
      }
      case Orbit::S4:
        append_permutations({0, 0, 0, 0}, {0.25}, o.w, rule);
        break;
      case Orbit::S31:
        append_permutations({0, 0, 0, 1}, {a, 1 - 3 * a}, o.w, rule);
        break;
      case Orbit::S22:
        append_permutations({0, 0, 1, 1}, {a, 0.5 - a}, o.w, rule);
        break;
      case Orbit::S211:
        append_permutations({0, 0, 1, 2}, {a, b, 1 - 2 * a - b}, o.w, rule);
        break;
    }
  }
  return rule;
}

std::vector<TabulatedRule> tables(int dim) {
  using O = Orbit;
  if (dim == 2) {
    return {
        // Centroid, degree 1.
        {2, 1, {{O::S3, 0, 0, 0.5}}},
        // 3 interior points, degree 2 (Strang-Fix).
        {2, 2, {{O::S21, 1.0 / 6.0, 0, 1.0 / 6.0}}},
        // Strang-Fix / Dunavant 6 points, degree 4.
        {2,
         4,
         {{O::S21, 0.44594849091596488632, 0, 0.11169079483900573285},
          {O::S21, 0.09157621350977074346, 0, 0.054975871827660933819}}},
        // Radon 7 points, degree 5: a = (6 ∓ √15)/21, w = (155 ∓ √15)/2400.
        {2,
         5,
         {{O::S3, 0, 0, 0.1125},
          {O::S21, 0.47014206410511508977, 0, 0.066197076394253090369},
          {O::S21, 0.1012865073234563388, 0, 0.062969590272413576298}}},
        // Dunavant 12 points, degree 6.
        {2,
         6,
         {{O::S21, 0.24928674517091042129, 0, 0.058393137863189683013},
          {O::S21, 0.06308901449150222834, 0, 0.02542245318510340846},
          {O::S111, 0.053145049844816947353, 0.31035245103378440542, 0.041425537809186787597}}},
        // Gatermann 12 points, degree 7 (rotational symmetry only).
        {2,
         7,
         {{O::C3, 0.87009986783168179638, 0.062382265094402118174, 0.026517028157436251429},
          {O::C3, 0.6232720494910915656, 0.055225456656926611737, 0.043881408714446055037},
          {O::C3, 0.30472650086816719592, 0.03432430294509714647, 0.028775042784981585738},
          {O::C3, 0.20644149867001643817, 0.51584233435359177926, 0.067493187009802774463}}},
        // Dunavant 16 points, degree 8.
        {2,
         8,
         {{O::S3, 0, 0, 0.072157803838893584126},
          {O::S21, 0.45929258829272315603, 0, 0.047545817133642312397},
          {O::S21, 0.17056930775176020662, 0, 0.051608685267359125141},
          {O::S21, 0.050547228317030975458, 0, 0.016229248811599040155},
          {O::S111, 0.0083947774099576053372, 0.26311282963463811342, 0.013615157087217497132}}},
        // Dunavant 19 points, degree 9.
        {2,
         9,
         {{O::S3, 0, 0, 0.04856789814139941691},
          {O::S21, 0.48968251919873762778, 0, 0.015667350113569535268},
          {O::S21, 0.43708959149293663727, 0, 0.038913770502387139658},
          {O::S21, 0.18820353561903273024, 0, 0.039823869463605126516},
          {O::S21, 0.044729513394452709865, 0, 0.012788837829349015631},
          {O::S111, 0.036838412054736283635, 0.22196298916076569568, 0.021641769688644688645}}},
        // Dunavant 25 points, degree 10.
        {2,
         10,
         {{O::S3, 0, 0, 0.045408995191376790048},
          {O::S21, 0.48557763338365737737, 0, 0.018362978878233352359},
          {O::S21, 0.1094815754850370548, 0, 0.022660529717763967391},
          {O::S111, 0.14170721941487995476, 0.30793983876412095017, 0.036378958422710054302},
          {O::S111, 0.025003534762686386074, 0.24667256063990269392, 0.014163621265528742418},
          {O::S111, 0.0095408154002994575802, 0.066803251012200265774, 0.00471083348186641173}}},
    };
  }
  if (dim == 3) {
    return {
        // Centroid, degree 1.
        {3, 1, {{O::S4, 0, 0, 1.0 / 6.0}}},
        // 4 points, degree 2: a = (5 - √5)/20.
        {3, 2, {{O::S31, (5.0 - std::sqrt(5.0)) / 20.0, 0, 1.0 / 24.0}}},
        // 14 points, degree 5 (two S31 orbits and one S22 orbit; positive weights).
        {3,
         5,
         {{O::S31, 0.092735250310891226402, 0, 0.012248840519393658257},
          {O::S31, 0.3108859192633006098, 0, 0.0187813209530026418},
          {O::S22, 0.045503704125649649492, 0, 0.007091003462846911073}}},
        // Keast 24 points, degree 6.
        {3,
         6,
         {{O::S31, 0.21460287125915202929, 0, 0.0066537917096945820166},
          {O::S31, 0.040673958534611353116, 0, 0.0016795351758867738247},
          {O::S31, 0.32233789014227551034, 0, 0.0092261969239424536825},
          {O::S211, 0.063661001875017525299, 0.26967233145831580803, 27.0 / 3360.0}}},
    };
  }
  return {};
}

std::string describe(int dim, int degree) {
  return "dimension " + std::to_string(dim) + ", degree " + std::to_string(degree);
}

void check_arguments(int dim, int degree) {
  if (dim < 1 || dim > 3)
    throw InputError("simplex quadrature: dimension must be 1, 2 or 3 (got " +
                     describe(dim, degree) + ")");
  if (degree < 0 || degree > max_quadrature_degree)
    throw InputError("simplex quadrature: degree must be in 0.." +
                     std::to_string(max_quadrature_degree) + " (got " + describe(dim, degree) +
                     ")");
}

}  // namespace

double reference_simplex_measure(int dim) {
  double factorial = 1;
  for (int k = 2; k <= dim; ++k) factorial *= k;
  return 1.0 / factorial;
}

void gauss_jacobi(int n, double alpha, std::vector<double>& nodes, std::vector<double>& weights) {
  COAPT_ASSERT(n >= 1 && alpha > -1, "gauss_jacobi needs n >= 1 and alpha > -1");
  // Three-term recurrence of the monic polynomials orthogonal for (1 - u)^alpha on [0, 1]:
  // the Jacobi (alpha, 0) coefficients on [-1, 1] mapped by u = (1 + x)/2.
  std::vector<double> a(n), sqrt_b(n + 1, 0.0);
  for (int k = 0; k < n; ++k) {
    const double s = 2.0 * k + alpha;
    const double ak = k == 0 ? -alpha / (alpha + 2) : -alpha * alpha / (s * (s + 2));
    a[k] = 0.5 * (1 + ak);
  }
  for (int k = 1; k <= n; ++k) {
    const double s = 2.0 * k + alpha;
    const double bk = 4.0 * k * (k + alpha) * k * (k + alpha) / (s * s * (s + 1) * (s - 1));
    sqrt_b[k] = 0.5 * std::sqrt(bk);
  }
  const double mu0 = 1.0 / (alpha + 1);

  // Golub-Welsch: the nodes are the eigenvalues of the symmetric tridiagonal Jacobi matrix.
  Eigen::VectorXd diagonal(n), subdiagonal(n > 1 ? n - 1 : 0);
  for (int k = 0; k < n; ++k) diagonal[k] = a[k];
  for (int k = 1; k < n; ++k) subdiagonal[k - 1] = sqrt_b[k];
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver;
  solver.computeFromTridiagonal(diagonal, subdiagonal, Eigen::EigenvaluesOnly);
  COAPT_ASSERT(solver.info() == Eigen::Success, "Gauss-Jacobi eigenvalue problem failed");

  // Newton on the orthonormal p_n polishes each node to full precision; the weights are
  // the Christoffel numbers 1 / sum_{k<n} p_k(u)^2, which are accurate to the last bits.
  auto evaluate = [&](double u, double& p, double& dp, double& sum_squares) {
    double p_prev = 0, dp_prev = 0;
    p = 1.0 / std::sqrt(mu0);
    dp = 0;
    sum_squares = 0;
    for (int k = 0; k < n; ++k) {
      sum_squares += p * p;
      const double p_next = ((u - a[k]) * p - sqrt_b[k] * p_prev) / sqrt_b[k + 1];
      const double dp_next = (p + (u - a[k]) * dp - sqrt_b[k] * dp_prev) / sqrt_b[k + 1];
      p_prev = p;
      dp_prev = dp;
      p = p_next;
      dp = dp_next;
    }
  };
  nodes.resize(n);
  weights.resize(n);
  for (int i = 0; i < n; ++i) {
    double u = solver.eigenvalues()[i];
    double p = 0, dp = 0, sum_squares = 0;
    for (int iteration = 0; iteration < 3; ++iteration) {
      evaluate(u, p, dp, sum_squares);
      if (dp == 0) break;
      const double step = p / dp;
      u -= step;
      if (std::abs(step) <= 1e-17) break;
    }
    evaluate(u, p, dp, sum_squares);
    nodes[i] = u;
    weights[i] = 1.0 / sum_squares;
  }
}

QuadratureRule collapsed_simplex_quadrature(int dim, int degree) {
  check_arguments(dim, degree);
  const int m = degree / 2 + 1;
  // x_1 = u_1, x_2 = (1 - u_1) u_2, x_3 = (1 - u_1)(1 - u_2) u_3: the Jacobian
  // (1 - u_1)^(dim-1) (1 - u_2)^(dim-2) ... is the Gauss-Jacobi weight of each direction.
  std::vector<double> u[3], w[3];
  for (int k = 0; k < dim; ++k) gauss_jacobi(m, dim - 1 - k, u[k], w[k]);

  QuadratureRule rule;
  rule.dim = dim;
  rule.degree = 2 * m - 1;
  int n_points = 1;
  for (int k = 0; k < dim; ++k) n_points *= m;
  rule.points.reserve(static_cast<std::size_t>(n_points) * dim);
  rule.weights.reserve(n_points);
  int index[3] = {0, 0, 0};
  for (int q = 0; q < n_points; ++q) {
    int rest = q;
    for (int k = dim - 1; k >= 0; --k) {
      index[k] = rest % m;
      rest /= m;
    }
    double scale = 1, weight = 1;
    for (int k = 0; k < dim; ++k) {
      const double uk = u[k][index[k]];
      rule.points.push_back(scale * uk);
      scale *= 1 - uk;
      weight *= w[k][index[k]];
    }
    rule.weights.push_back(weight);
  }
  return rule;
}

const std::vector<QuadratureRule>& tabulated_simplex_quadratures(int dim) {
  static const std::vector<QuadratureRule> rules[4] = {{},
                                                       {},
                                                       [] {
                                                         std::vector<QuadratureRule> r;
                                                         for (const auto& t : tables(2))
                                                           r.push_back(expand(t));
                                                         return r;
                                                       }(),
                                                       [] {
                                                         std::vector<QuadratureRule> r;
                                                         for (const auto& t : tables(3))
                                                           r.push_back(expand(t));
                                                         return r;
                                                       }()};
  check_arguments(dim, 0);
  return rules[dim];
}

const QuadratureRule& simplex_quadrature(int dim, int degree) {
  check_arguments(dim, degree);
  static std::mutex mutex;
  static std::map<std::pair<int, int>, QuadratureRule> cache;  // node-based: references stay valid
  std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_pair(dim, degree);
  if (auto found = cache.find(key); found != cache.end()) return found->second;

  // The cheapest tabulated rule of sufficient degree (lowest degree first on ties), unless
  // the collapsed rule has strictly fewer points.
  const QuadratureRule* best = nullptr;
  for (const auto& rule : tabulated_simplex_quadratures(dim))
    if (rule.degree >= degree && (best == nullptr || rule.size() < best->size())) best = &rule;
  QuadratureRule collapsed = collapsed_simplex_quadrature(dim, degree);
  if (best == nullptr || collapsed.size() < best->size())
    return cache.emplace(key, std::move(collapsed)).first->second;
  return cache.emplace(key, *best).first->second;
}

}  // namespace coapt::fem
