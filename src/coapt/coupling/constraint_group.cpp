#include "coapt/coupling/constraint_group.hpp"

#include <petscvec.h>

#include <algorithm>

#include "coapt/core/error.hpp"

namespace coapt::coupling {
namespace {

/// The owned entries of a slave-layout vector of the transfer (one value per fluid vertex).
std::vector<double> owned_values(Vec vector, std::size_t n) {
  const PetscScalar* values = nullptr;
  COAPT_PETSC_CHECK(VecGetArrayRead(vector, &values));
  std::vector<double> copy(values, values + n);
  COAPT_PETSC_CHECK(VecRestoreArrayRead(vector, &values));
  return copy;
}

}  // namespace

ConstraintGroup::ConstraintGroup(const mesh::Mesh& fluid,
                                 std::vector<ImmersedConstraint*> constraints, double threshold,
                                 std::vector<char> fixed)
    : fluid_(fluid),
      constraints_(std::move(constraints)),
      threshold_(threshold),
      fixed_(std::move(fixed)),
      slots_(constraints_.size()) {
  if (!fixed_.empty() && fixed_.size() != static_cast<std::size_t>(fluid.n_owned_vertices))
    throw InternalError("constraint group: `fixed` must have one entry per owned fluid vertex");
  for (auto* constraint : constraints_) constraint->set_shared(constraints_.size() > 1);
}

void ConstraintGroup::combine() {
  if (constraints_.size() < 2) return;
  const auto n = static_cast<std::size_t>(fluid_.n_owned_vertices);
  std::vector<std::vector<double>> coverage, dual;
  bool frozen = false;
  for (const auto* constraint : constraints_) {
    coverage.push_back(owned_values(constraint->transfer().coverage(), n));
    dual.push_back(owned_values(constraint->transfer().dual_mass(), n));
    frozen = frozen || constraint->frozen();
  }
  // The constrained set: the union of the frozen sets, or Σ_k c_k,i ≥ t.
  std::vector<char> member(n, 0);
  if (frozen) {
    for (const auto* constraint : constraints_)
      for (const int v : constraint->constrained_vertices())
        member[static_cast<std::size_t>(v)] = 1;
  } else {
    for (std::size_t v = 0; v < n; ++v) {
      if (!fixed_.empty() && fixed_[v]) continue;
      double covered = 0;
      for (const auto& c : coverage) covered += c[v];
      member[v] = covered >= threshold_ ? 1 : 0;
    }
  }
  // D_i = Σ_k D_k,i over the solids that overlap the node's support; T needs D_i > 0.
  std::vector<double> total(n, 0.0);
  for (std::size_t v = 0; v < n; ++v) {
    if (!member[v]) continue;
    double sum = 0;
    for (std::size_t k = 0; k < constraints_.size(); ++k)
      if (coverage[k][v] > 0.0) sum += dual[k][v];
    total[v] = sum;
    if (!(sum > 0.0)) member[v] = 0;
  }
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    std::vector<int> vertices;
    std::vector<double> duals;
    for (std::size_t v = 0; v < n; ++v)
      if (member[v] && coverage[k][v] > 0.0) {
        vertices.push_back(static_cast<int>(v));
        duals.push_back(total[v]);
      }
    constraints_[k]->assign(std::move(vertices), std::move(duals));
    constraints_[k]->drop_partial(member);  // a node the group constrains is no longer partial
  }
}

MergedConstraint ConstraintGroup::merge(const std::vector<std::vector<double>>& shares) {
  if (shares.size() != constraints_.size())
    throw InternalError("constraint group: one share array per solid");
  const auto dim = static_cast<std::size_t>(fluid_.dim);
  MergedConstraint merged;
  for (const auto* constraint : constraints_) {
    const auto& own = constraint->constrained_vertices();
    merged.vertices.insert(merged.vertices.end(), own.begin(), own.end());
  }
  std::sort(merged.vertices.begin(), merged.vertices.end());
  merged.vertices.erase(std::unique(merged.vertices.begin(), merged.vertices.end()),
                        merged.vertices.end());
  merged.velocities.assign(merged.vertices.size() * dim, 0.0);
  for (std::size_t k = 0; k < constraints_.size(); ++k) {
    const auto& own = constraints_[k]->constrained_vertices();
    if (shares[k].size() != own.size() * dim)
      throw InternalError("constraint group: a share per constrained vertex and component");
    slots_[k].clear();
    for (std::size_t q = 0; q < own.size(); ++q) {
      const auto slot = static_cast<std::size_t>(
          std::lower_bound(merged.vertices.begin(), merged.vertices.end(), own[q]) -
          merged.vertices.begin());
      slots_[k].push_back(slot);
      for (std::size_t i = 0; i < dim; ++i)
        merged.velocities[slot * dim + i] += shares[k][q * dim + i];
    }
  }
  return merged;
}

std::vector<double> ConstraintGroup::reactions_of(std::size_t k,
                                                  const std::vector<double>& reactions) const {
  const auto dim = static_cast<std::size_t>(fluid_.dim);
  std::vector<double> own(slots_.at(k).size() * dim);
  for (std::size_t q = 0; q < slots_[k].size(); ++q) {
    if ((slots_[k][q] + 1) * dim > reactions.size())
      throw InternalError("constraint group: reactions of another merge");
    for (std::size_t i = 0; i < dim; ++i) own[q * dim + i] = reactions[slots_[k][q] * dim + i];
  }
  return own;
}

std::vector<double> ConstraintGroup::cell_coverage() const {
  std::vector<double> sum(static_cast<std::size_t>(fluid_.n_owned_cells), 0.0);
  for (const auto* constraint : constraints_) {
    const auto& own = constraint->transfer().cell_coverage();
    for (std::size_t c = 0; c < sum.size(); ++c) sum[c] += own[c];
  }
  return sum;
}

}  // namespace coapt::coupling
