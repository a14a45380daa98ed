// IQN-ILS (quasi_newton.hpp): the columns of this step and of past steps, the least-squares
// problem by modified Gram–Schmidt with a filter, and the update.
#include "coapt/coupling/quasi_newton.hpp"

#include <cmath>

#include "coapt/core/error.hpp"

namespace coapt::coupling {

InterfaceQuasiNewton::InterfaceQuasiNewton(MPI_Comm comm, int reuse_steps, int max_columns,
                                           double filter)
    : comm_(comm), reuse_steps_(reuse_steps), max_columns_(max_columns), filter_(filter) {}

double InterfaceQuasiNewton::dot(std::span<const double> a, std::span<const double> b) const {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += a[i] * b[i];
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return sum;
}

void InterfaceQuasiNewton::begin_step() {
  current_ = Columns{};
  last_residual_.clear();
  last_x_tilde_.clear();
  reused_dropped_ = false;
}

void InterfaceQuasiNewton::drop_reused() {
  reused_dropped_ = true;
}

void InterfaceQuasiNewton::reset() {
  begin_step();
  previous_.clear();
}

void InterfaceQuasiNewton::end_step() {
  if (reuse_steps_ <= 0) return;
  if (reused_dropped_) previous_.clear();
  reused_dropped_ = false;
  if (!current_.v.empty()) previous_.push_front(std::move(current_));
  while (static_cast<int>(previous_.size()) > reuse_steps_) previous_.pop_back();
  current_ = Columns{};
}

void InterfaceQuasiNewton::restore_reused(std::deque<Columns> columns) {
  previous_ = std::move(columns);
  while (static_cast<int>(previous_.size()) > reuse_steps_) previous_.pop_back();
}

int InterfaceQuasiNewton::next(std::span<const double> x, std::span<const double> x_tilde,
                               double omega, std::span<double> next_x) {
  const std::size_t n = x.size();
  if (x_tilde.size() != n || next_x.size() != n)
    throw InternalError("InterfaceQuasiNewton::next: vectors of different lengths");
  std::vector<double> residual(n);
  for (std::size_t i = 0; i < n; ++i) residual[i] = x_tilde[i] - x[i];
  if (!last_residual_.empty()) {  // a new column pair from the last iterate
    std::vector<double> dv(n), dw(n);
    for (std::size_t i = 0; i < n; ++i) {
      dv[i] = residual[i] - last_residual_[i];
      dw[i] = x_tilde[i] - last_x_tilde_[i];
    }
    current_.v.push_back(std::move(dv));
    current_.w.push_back(std::move(dw));
  }
  last_residual_ = residual;
  last_x_tilde_.assign(x_tilde.begin(), x_tilde.end());

  // The columns, newest first: this step's, then the previous steps'.
  std::vector<const std::vector<double>*> v_columns, w_columns;
  for (auto k = current_.v.size(); k-- > 0;) {
    v_columns.push_back(&current_.v[k]);
    w_columns.push_back(&current_.w[k]);
  }
  if (!reused_dropped_)
    for (const auto& step : previous_)
      for (auto k = step.v.size(); k-- > 0;) {
        v_columns.push_back(&step.v[k]);
        w_columns.push_back(&step.w[k]);
      }
  if (static_cast<int>(v_columns.size()) > max_columns_) {
    v_columns.resize(static_cast<std::size_t>(max_columns_));
    w_columns.resize(static_cast<std::size_t>(max_columns_));
  }

  // Modified Gram–Schmidt: V_kept = Q R, Q orthonormal columns.
  std::vector<std::vector<double>> q;
  std::vector<std::vector<double>> r;  // r[j][i]: column j's coefficient on q_i (i ≤ j)
  std::vector<std::size_t> kept;
  for (std::size_t j = 0; j < v_columns.size(); ++j) {
    std::vector<double> column = *v_columns[j];
    const double original = std::sqrt(dot(column, column));
    if (!(original > 0)) continue;
    std::vector<double> coefficients(q.size() + 1, 0.0);
    for (std::size_t i = 0; i < q.size(); ++i) {
      coefficients[i] = dot(q[i], column);
      for (std::size_t k = 0; k < n; ++k) column[k] -= coefficients[i] * q[i][k];
    }
    const double norm = std::sqrt(dot(column, column));
    if (norm < filter_ * original) continue;  // nearly dependent: dropped
    for (double& value : column) value /= norm;
    coefficients[q.size()] = norm;
    q.push_back(std::move(column));
    r.push_back(std::move(coefficients));
    kept.push_back(j);
  }
  if (q.empty()) {
    for (std::size_t i = 0; i < n; ++i) next_x[i] = x[i] + omega * residual[i];
    return 0;
  }
  // R c = −Qᵀ r by back substitution.
  const std::size_t m = q.size();
  std::vector<double> c(m);
  for (std::size_t i = 0; i < m; ++i) c[i] = -dot(q[i], residual);
  for (std::size_t i = m; i-- > 0;) {
    for (std::size_t j = i + 1; j < m; ++j) c[i] -= r[j][i] * c[j];
    c[i] /= r[i][i];
  }
  for (std::size_t i = 0; i < n; ++i) next_x[i] = x_tilde[i];
  for (std::size_t j = 0; j < m; ++j) {
    const auto& w = *w_columns[kept[j]];
    for (std::size_t i = 0; i < n; ++i) next_x[i] += c[j] * w[i];
  }
  return static_cast<int>(m);
}

}  // namespace coapt::coupling
