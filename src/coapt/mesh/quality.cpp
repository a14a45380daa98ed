#include "coapt/mesh/quality.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "coapt/core/error.hpp"

namespace coapt::mesh {
namespace {

// Points of local cell c.
void cell_points(const Mesh& mesh, int c, const double* (&points)[4]) {
  const auto vertices = mesh.cell(c);
  for (int k = 0; k <= mesh.dim; ++k) points[k] = mesh.point(vertices[k]).data();
}

// Mean of |signed measure| over the cells, and the threshold for degeneracy.
double degenerate_threshold(const std::vector<double>& measures) {
  if (measures.empty()) return 0;
  double sum = 0;
  std::size_t n = 0;
  for (const double m : measures)
    if (std::isfinite(m)) {
      sum += std::abs(m);
      ++n;
    }
  return n == 0 ? 0 : kDegenerateFraction * sum / static_cast<double>(n);
}

std::vector<double> signed_measures(const Mesh& mesh) {
  std::vector<double> measures(static_cast<std::size_t>(mesh.n_cells()));
  for (int c = 0; c < mesh.n_cells(); ++c) measures[c] = cell_signed_measure(mesh, c);
  return measures;
}

CellIssue make_issue(const Mesh& mesh, int c, double measure) {
  CellIssue issue;
  issue.cell = c;
  issue.original = c < static_cast<int>(mesh.original_cell.size()) ? mesh.original_cell[c] : c + 1;
  issue.measure = measure;
  const auto vertices = mesh.cell(c);
  for (const int v : vertices) {
    const auto p = mesh.point(v);
    for (int d = 0; d < mesh.dim; ++d) issue.centroid[d] += p[d] / (mesh.dim + 1);
  }
  return issue;
}

std::string describe(const std::vector<CellIssue>& issues, const char* what) {
  constexpr std::size_t kListed = 5;
  std::string text = fmt::format("{} element", what);
  for (std::size_t i = 0; i < std::min(issues.size(), kListed); ++i) {
    const auto& e = issues[i];
    text += fmt::format("{} {} at ({:.6g}, {:.6g}, {:.6g})", i == 0 ? "" : ", element", e.original,
                        e.centroid[0], e.centroid[1], e.centroid[2]);
  }
  if (issues.size() > kListed) text += ", ...";
  text += fmt::format(" ({} {} element{} in total)", issues.size(), what,
                      issues.size() == 1 ? "" : "s");
  return text;
}

}  // namespace

double shape_quality(int dim, const double* const* p) {
  const double measure = std::abs(signed_measure(dim, p));
  double sum_sq = 0;
  for (int i = 0; i <= dim; ++i)
    for (int j = i + 1; j <= dim; ++j)
      for (int d = 0; d < dim; ++d) sum_sq += (p[j][d] - p[i][d]) * (p[j][d] - p[i][d]);
  if (sum_sq <= 0) return 0;
  if (dim == 2) return 4.0 * std::sqrt(3.0) * measure / sum_sq;
  return 12.0 * std::cbrt(3.0 * measure * 3.0 * measure) / sum_sq;
}

double cell_shape_quality(const Mesh& mesh, int c) {
  const double* points[4] = {};
  cell_points(mesh, c, points);
  return shape_quality(mesh.dim, points);
}

QualityReport check_quality(const Mesh& mesh) {
  QualityReport report;
  report.source = mesh.source;
  report.dim = mesh.dim;
  report.n_cells = mesh.n_cells();
  if (mesh.n_cells() == 0) return report;

  const auto measures = signed_measures(mesh);
  const double threshold = degenerate_threshold(measures);
  report.min_measure = std::numeric_limits<double>::infinity();
  report.max_measure = -std::numeric_limits<double>::infinity();
  report.min_shape = std::numeric_limits<double>::infinity();
  report.max_shape = -std::numeric_limits<double>::infinity();
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const double m = measures[c];
    report.min_measure = std::min(report.min_measure, m);
    report.max_measure = std::max(report.max_measure, m);
    report.total_measure += std::abs(m);
    const double q = cell_shape_quality(mesh, c);
    report.min_shape = std::min(report.min_shape, q);
    report.max_shape = std::max(report.max_shape, q);
    // A NaN/inf measure (bad coordinates) counts as degenerate, not silently accepted.
    if (!std::isfinite(m) || std::abs(m) < threshold || m == 0)
      report.degenerate.push_back(make_issue(mesh, c, m));
    else if (m < 0)
      report.inverted.push_back(make_issue(mesh, c, m));
  }
  return report;
}

bool orient_cells(Mesh& mesh) {
  if (mesh.n_cells() == 0) return false;
  const auto measures = signed_measures(mesh);
  const double threshold = degenerate_threshold(measures);
  std::size_t n_positive = 0, n_negative = 0;
  for (const double m : measures) {
    if (m > threshold) ++n_positive;
    if (m < -threshold) ++n_negative;
  }
  if (n_positive > 0 || n_negative == 0) return false;
  const int per_cell = mesh.dim + 1;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    int* vertices = mesh.cells.data() + static_cast<std::size_t>(c) * per_cell;
    std::swap(vertices[per_cell - 2], vertices[per_cell - 1]);
  }
  return true;
}

void require_valid(const Mesh& mesh, const QualityReport& report) {
  if (report.valid()) return;
  std::string message = mesh.source + ": ";
  if (!report.inverted.empty()) message += describe(report.inverted, "inverted");
  if (!report.degenerate.empty()) {
    if (!report.inverted.empty()) message += "; ";
    message += describe(report.degenerate, "degenerate");
    message +=
        fmt::format(" (|measure| below {:g} times the mean cell measure)", kDegenerateFraction);
  }
  throw InputError(message);
}

}  // namespace coapt::mesh
