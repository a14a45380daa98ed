/// @file mortar.cpp
/// Mortar search, projection-plane integration and the dual-basis operators (mortar.hpp).

#include "coapt/contact/mortar.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "coapt/core/error.hpp"
#include "coapt/transfer/clipping.hpp"
#include "coapt/transfer/geometry.hpp"

namespace coapt::contact {

namespace {

using Point3 = std::array<double, 3>;

double dot3(const Point3& a, const Point3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point3 cross3(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Point3 minus3(const Point3& a, const Point3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

/// Relative length below which a clipped overlap counts as empty (round-off of touching
/// facets).
constexpr double kEmptyOverlap = 1e-12;

/// A slave facet counts as wholly covered when the master covers this close to its measure
/// (relative); its dual functions are then the standard ones.
constexpr double kWholeFacet = 1e-8;
/// A slave facet covered by less than this fraction of its measure adds nothing to the
/// operators: its covered mass matrix is too near singular for the modified dual functions
/// (only its coverage ∫_Γc N_j counts).
constexpr double kMinFacetCoverage = 1e-3;

/// Sorts entries by (row, column) and sums duplicates.
std::vector<MortarEntry> merge(std::vector<MortarEntry> entries) {
  std::sort(entries.begin(), entries.end(), [](const MortarEntry& a, const MortarEntry& b) {
    return a.row != b.row ? a.row < b.row : a.column < b.column;
  });
  std::vector<MortarEntry> merged;
  for (const auto& e : entries) {
    if (!merged.empty() && merged.back().row == e.row && merged.back().column == e.column)
      merged.back().value += e.value;
    else
      merged.push_back(e);
  }
  return merged;
}

}  // namespace

int integrate_segments(const std::array<std::array<double, 2>, 2>& slave,
                       const std::array<std::array<double, 2>, 2>& master, MortarPoint* points) {
  const double tx = slave[1][0] - slave[0][0], ty = slave[1][1] - slave[0][1];
  const double length2 = tx * tx + ty * ty;
  if (!(length2 > 0.0)) return 0;
  // Slave parameter ξ ∈ [0, 1] of the master vertices' orthogonal projections.
  const auto parameter = [&](const std::array<double, 2>& y) {
    return ((y[0] - slave[0][0]) * tx + (y[1] - slave[0][1]) * ty) / length2;
  };
  const double xi_c = parameter(master[0]), xi_d = parameter(master[1]);
  if (!(std::fabs(xi_d - xi_c) > kEmptyOverlap)) return 0;  // master orthogonal to the slave
  const double lower = std::max(0.0, std::min(xi_c, xi_d));
  const double upper = std::min(1.0, std::max(xi_c, xi_d));
  if (!(upper - lower > kEmptyOverlap)) return 0;
  // 2-point Gauss on [lower, upper]: exact for the quadratic products Φ_j N_k.
  const double half = 0.5 * (upper - lower), middle = 0.5 * (upper + lower);
  const double offset = half / std::sqrt(3.0);
  const double weight = std::sqrt(length2) * half;
  for (int q = 0; q < 2; ++q) {
    const double xi = q == 0 ? middle - offset : middle + offset;
    const double eta = (xi - xi_c) / (xi_d - xi_c);  // master parameter (affine in ξ)
    points[q].slave = {1.0 - xi, xi, 0.0};
    points[q].master = {1.0 - eta, eta, 0.0};
    points[q].weight = weight;
  }
  return 2;
}

int integrate_triangles(const std::array<std::array<double, 3>, 3>& slave,
                        const std::array<std::array<double, 3>, 3>& master, MortarPoint* points) {
  const Point3 e1_raw = minus3(slave[1], slave[0]);
  const Point3 normal_raw = cross3(e1_raw, minus3(slave[2], slave[0]));
  const double e1_norm = std::sqrt(dot3(e1_raw, e1_raw));
  const double normal_norm = std::sqrt(dot3(normal_raw, normal_raw));
  if (!(e1_norm > 0.0) || !(normal_norm > 0.0)) return 0;
  const Point3 e1 = {e1_raw[0] / e1_norm, e1_raw[1] / e1_norm, e1_raw[2] / e1_norm};
  const Point3 normal = {normal_raw[0] / normal_norm, normal_raw[1] / normal_norm,
                         normal_raw[2] / normal_norm};
  const Point3 e2 = cross3(normal, e1);
  // Coordinates in the slave's plane; projecting along the normal preserves slave areas.
  const auto plane = [&](const Point3& y) {
    const Point3 d = minus3(y, slave[0]);
    return transfer::Point<2>{dot3(d, e1), dot3(d, e2)};
  };
  const auto s = transfer::make_simplex<2>({plane(slave[0]), plane(slave[1]), plane(slave[2])});
  const auto m = transfer::make_simplex<2>({plane(master[0]), plane(master[1]), plane(master[2])});
  if (s.degenerate() || m.degenerate()) return 0;
  transfer::ConvexPolygon polygon;
  polygon.assign_triangle(s.vertices);
  for (int j = 0; j < 3; ++j) {
    // λ^m_j ≥ 0: the half-plane of the projected master triangle across its face j.
    const auto h = transfer::HalfSpace<2>::through(m.gradients[j],
                                                   m.vertices[transfer::Simplex<2>::anchor(j)]);
    if (!polygon.clip(h, kEmptyOverlap)) return 0;
  }
  std::array<transfer::QuadraturePoint<2>, transfer::ConvexPolygon::max_quadrature_points> rule;
  const int n = polygon.quadrature(rule.data());
  for (int q = 0; q < n; ++q) {
    for (int i = 0; i < 3; ++i) {
      points[q].slave[i] = s.barycentric(i, rule[q].point);
      points[q].master[i] = m.barycentric(i, rule[q].point);
    }
    points[q].weight = rule[q].weight;
  }
  return n;
}

std::array<std::array<double, 3>, 3> dual_coefficients(int n_vertices,
                                                       const std::array<bool, 3>& multiplier,
                                                       const FacetMass* covered_mass) {
  std::array<std::array<double, 3>, 3> standard{}, result{};
  if (covered_mass == nullptr) {
    for (int a = 0; a < n_vertices; ++a)
      for (int b = 0; b < n_vertices; ++b) standard[a][b] = (a == b ? n_vertices + 1.0 : 0.0) - 1.0;
  } else {
    // A⁰ = diag(d) M⁻¹ with d_a = Σ_b M_ab (M symmetric positive definite).
    using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
    Small M(n_vertices, n_vertices);
    for (int a = 0; a < n_vertices; ++a)
      for (int b = 0; b < n_vertices; ++b) M(a, b) = (*covered_mass)[a][b];
    const Eigen::LDLT<Small> factor(M);
    if (factor.info() != Eigen::Success || !factor.isPositive())
      throw InternalError("dual_coefficients: the covered mass matrix is not positive definite");
    const Small inverse = factor.solve(Small::Identity(n_vertices, n_vertices));
    const Eigen::VectorXd d = M.rowwise().sum();
    for (int a = 0; a < n_vertices; ++a)
      for (int b = 0; b < n_vertices; ++b) standard[a][b] = d(a) * inverse(a, b);
  }
  int n_multipliers = 0;
  for (int a = 0; a < n_vertices; ++a) n_multipliers += multiplier[a] ? 1 : 0;
  if (n_multipliers == 0) return result;
  for (int a = 0; a < n_vertices; ++a) {
    if (!multiplier[a]) continue;
    result[a] = standard[a];
    for (int b = 0; b < n_vertices; ++b)
      if (!multiplier[b])
        for (int k = 0; k < n_vertices; ++k) result[a][k] += standard[b][k] / n_multipliers;
  }
  return result;
}

MortarOperators assemble_mortar(const Surface& slave, std::span<const double> slave_x,
                                const Surface& master, std::span<const double> master_x,
                                const MortarOptions& options) {
  const int dim = slave.dim;
  if (master.dim != dim) throw InternalError("assemble_mortar: surfaces of different dimension");
  const std::size_t n_slave = static_cast<std::size_t>(slave.n_nodes());
  MortarOperators result;
  result.coverage_threshold = options.coverage_threshold;
  std::vector<char> valid;
  result.normals = nodal_normals(slave, slave_x, &valid);
  if (!options.fixed_components.empty())
    for (std::size_t j = 0; j < n_slave; ++j) {
      double* n = result.normals.data() + j * dim;
      double norm = 0.0;
      for (int i = 0; i < dim; ++i) {
        if (options.fixed_components[j * dim + i]) n[i] = 0.0;
        norm += n[i] * n[i];
      }
      norm = std::sqrt(norm);
      if (norm > 0.5) {  // else the surface is nearly normal to the fixed directions: no normal
        for (int i = 0; i < dim; ++i) n[i] /= norm;
      } else if (valid[j]) {
        for (int i = 0; i < dim; ++i) n[i] = 0.0;
        valid[j] = 0;
      }
    }
  result.multiplier = valid;
  if (options.boundary_modification) {
    const auto boundary = boundary_nodes(slave);
    for (std::size_t j = 0; j < n_slave; ++j)
      if (boundary[j]) result.multiplier[j] = 0;
  }
  result.dual_mass.assign(n_slave, 0.0);
  result.support.assign(n_slave, 0.0);
  result.covered.assign(n_slave, 0.0);
  result.weighted_gap.assign(n_slave, 0.0);

  // Bounding boxes of the master facets.
  const int n_master_facets = master.n_facets();
  std::vector<double> box(static_cast<std::size_t>(n_master_facets) * 2 * dim);
  for (int f = 0; f < n_master_facets; ++f) {
    double* lower = box.data() + static_cast<std::size_t>(f) * 2 * dim;
    double* upper = lower + dim;
    for (int i = 0; i < dim; ++i) {
      lower[i] = std::numeric_limits<double>::infinity();
      upper[i] = -std::numeric_limits<double>::infinity();
    }
    for (int node : master.facet(f))
      for (int i = 0; i < dim; ++i) {
        const double x = master_x[static_cast<std::size_t>(node) * dim + i];
        lower[i] = std::min(lower[i], x);
        upper[i] = std::max(upper[i], x);
      }
  }

  std::vector<MortarEntry> slave_entries, master_entries;
  std::array<MortarPoint, kMaxMortarPoints> points;
  std::vector<MortarPoint> facet_points;  // one slave facet's points, grouped by master facet
  std::vector<int> facet_masters;
  const double distance = options.search_distance;
  for (int s = 0; s < slave.n_facets(); ++s) {
    const auto sv = slave.facet(s);
    const auto slave_normal = facet_area_normal(slave, slave_x, s);
    const double slave_measure = std::sqrt(dot3(slave_normal, slave_normal));
    if (!(slave_measure > 0.0)) continue;
    const Point3 unit = {slave_normal[0] / slave_measure, slave_normal[1] / slave_measure,
                         slave_normal[2] / slave_measure};
    std::array<bool, 3> carries{};
    for (int a = 0; a < dim; ++a) carries[a] = result.multiplier[sv[a]] != 0;
    for (int a = 0; a < dim; ++a) result.support[sv[a]] += slave_measure / dim;
    // Slave facet box, grown by the search distance.
    double lower[3], upper[3];
    for (int i = 0; i < dim; ++i) {
      lower[i] = std::numeric_limits<double>::infinity();
      upper[i] = -std::numeric_limits<double>::infinity();
      for (int a = 0; a < dim; ++a) {
        const double x = slave_x[static_cast<std::size_t>(sv[a]) * dim + i];
        lower[i] = std::min(lower[i], x - distance);
        upper[i] = std::max(upper[i], x + distance);
      }
    }
    // Every master facet facing this slave facet: its quadrature points on the overlap.
    facet_points.clear();
    facet_masters.clear();
    const double* origin = slave_x.data() + static_cast<std::size_t>(sv[0]) * dim;
    for (int m = 0; m < n_master_facets; ++m) {
      const double* mlower = box.data() + static_cast<std::size_t>(m) * 2 * dim;
      const double* mupper = mlower + dim;
      bool overlap = true;
      for (int i = 0; i < dim && overlap; ++i)
        overlap = mlower[i] <= upper[i] && mupper[i] >= lower[i];
      if (!overlap) continue;
      const auto mv = master.facet(m);
      // Facing facets only (rejects the back of the master body).
      if (!(dot3(facet_area_normal(master, master_x, m), unit) < 0.0)) continue;
      // Within the search distance of the slave facet's plane.
      double nearest = std::numeric_limits<double>::infinity(),
             farthest = -std::numeric_limits<double>::infinity();
      for (int node : mv) {
        double d = 0.0;
        for (int i = 0; i < dim; ++i)
          d += (master_x[static_cast<std::size_t>(node) * dim + i] - origin[i]) * unit[i];
        nearest = std::min(nearest, d);
        farthest = std::max(farthest, d);
      }
      if (nearest > distance || farthest < -distance) continue;
      int n_points = 0;
      if (dim == 2) {
        std::array<std::array<double, 2>, 2> xs, xm;
        for (int a = 0; a < 2; ++a)
          for (int i = 0; i < 2; ++i) {
            xs[a][i] = slave_x[static_cast<std::size_t>(sv[a]) * 2 + i];
            xm[a][i] = master_x[static_cast<std::size_t>(mv[a]) * 2 + i];
          }
        n_points = integrate_segments(xs, xm, points.data());
      } else {
        std::array<std::array<double, 3>, 3> xs, xm;
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < 3; ++i) {
            xs[a][i] = slave_x[static_cast<std::size_t>(sv[a]) * 3 + i];
            xm[a][i] = master_x[static_cast<std::size_t>(mv[a]) * 3 + i];
          }
        n_points = integrate_triangles(xs, xm, points.data());
      }
      if (n_points == 0) continue;
      ++result.facet_pairs;
      for (int q = 0; q < n_points; ++q) {
        facet_points.push_back(points[q]);
        facet_masters.push_back(m);
      }
    }
    // The covered part Γc ∩ s: its measure, ∫ N_a and mass matrix ∫ N_a N_b.
    FacetMass covered_mass{};
    double covered_measure = 0.0;
    for (const auto& p : facet_points) {
      covered_measure += p.weight;
      for (int a = 0; a < dim; ++a)
        for (int b = 0; b < dim; ++b) covered_mass[a][b] += p.weight * p.slave[a] * p.slave[b];
    }
    if (!(covered_measure >= kMinFacetCoverage * slave_measure)) continue;
    for (const auto& p : facet_points)
      for (int a = 0; a < dim; ++a) result.covered[sv[a]] += p.weight * p.slave[a];
    // Dual functions biorthogonal on the covered part: the standard ones on a wholly covered
    // facet, else those of the covered mass matrix (file comment).
    const bool whole = std::fabs(covered_measure - slave_measure) <= kWholeFacet * slave_measure;
    const auto A =
        whole ? dual_coefficients(dim, carries) : dual_coefficients(dim, carries, &covered_mass);
    if (whole)  // Whole-facet integrals: ∫ N_a N_b = |s| (1 + δ_ab) / (n (n + 1)).
      for (int a = 0; a < dim; ++a) {
        double d = 0.0;
        for (int b = 0; b < dim; ++b)
          d += A[a][b] * slave_measure * (a == b ? 2.0 : 1.0) / (dim * (dim + 1));
        result.dual_mass[sv[a]] += d;
      }
    for (std::size_t begin = 0; begin < facet_points.size();) {
      const int m = facet_masters[begin];
      std::size_t end = begin;
      while (end < facet_points.size() && facet_masters[end] == m) ++end;
      const auto mv = master.facet(m);
      double ds[3][3] = {}, dm[3][3] = {};
      for (std::size_t q = begin; q < end; ++q) {
        const auto& p = facet_points[q];
        for (int a = 0; a < dim; ++a) {
          double phi = 0.0;
          for (int b = 0; b < dim; ++b) phi += A[a][b] * p.slave[b];
          for (int k = 0; k < dim; ++k) {
            ds[a][k] += p.weight * phi * p.slave[k];
            dm[a][k] += p.weight * phi * p.master[k];
          }
        }
      }
      for (int a = 0; a < dim; ++a) {
        if (!carries[a]) continue;
        if (!whole) result.dual_mass[sv[a]] += ds[a][a];
        for (int k = 0; k < dim; ++k) {
          slave_entries.push_back({sv[a], sv[k], ds[a][k]});
          master_entries.push_back({sv[a], mv[k], dm[a][k]});
        }
      }
      begin = end;
    }
  }
  result.slave_coupling = merge(std::move(slave_entries));
  result.master_coupling = merge(std::move(master_entries));
  // g̃_j = n_j · (Σ_l M_jl x^m_l − Σ_k D̂_jk x^s_k).
  for (const auto& e : result.master_coupling)
    for (int i = 0; i < dim; ++i)
      result.weighted_gap[e.row] += result.normals[static_cast<std::size_t>(e.row) * dim + i] *
                                    e.value *
                                    master_x[static_cast<std::size_t>(e.column) * dim + i];
  for (const auto& e : result.slave_coupling)
    for (int i = 0; i < dim; ++i)
      result.weighted_gap[e.row] -= result.normals[static_cast<std::size_t>(e.row) * dim + i] *
                                    e.value * slave_x[static_cast<std::size_t>(e.column) * dim + i];
  for (std::size_t j = 0; j < n_slave; ++j)
    if (!result.multiplier[j]) result.dual_mass[j] = 0.0;
  return result;
}

}  // namespace coapt::contact
