#include "coapt/coupling/immersed_constraint.hpp"

#include <fmt/format.h>
#include <mpi.h>

#include <algorithm>

#include "coapt/core/error.hpp"
#include "coapt/fem/assembly.hpp"

namespace coapt::coupling {
namespace {

/// Σ over the ranks of a local count. Collective.
PetscInt global_count(std::size_t local, MPI_Comm comm) {
  long long count = static_cast<long long>(local);
  MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_LONG_LONG, MPI_SUM, comm);
  return static_cast<PetscInt>(count);
}

}  // namespace

ImmersedConstraint::ImmersedConstraint(const mesh::Mesh& fluid, const mesh::Mesh& solid,
                                       const transfer::TransferOptions& options,
                                       std::vector<char> fixed, double partial_from)
    : fluid_(fluid),
      solid_(&solid),
      transfer_(std::make_unique<transfer::VariationalTransfer>(
          fluid, solid,
          [&] {
            auto with_primal = options;
            with_primal.primal = options.primal || partial_from < options.coverage_threshold;
            return with_primal;
          }())),
      fixed_(std::move(fixed)),
      partial_from_(partial_from) {
  if (!(partial_from > 0.0))
    throw InputError(
        fmt::format("immersed solid {}: the partial coverage must start above 0 "
                    "(got {})",
                    solid.source, partial_from));
  if (fluid.dim != solid.dim)
    throw InputError(fmt::format("immersed solid {} is {}D in a {}D fluid ({})", solid.source,
                                 solid.dim, fluid.dim, fluid.source));
  if (!fixed_.empty() && fixed_.size() != static_cast<std::size_t>(fluid.n_owned_vertices))
    throw InternalError("immersed constraint: `fixed` must have one entry per owned fluid vertex");
  COAPT_PETSC_CHECK(VecCreateMPI(fluid.comm,
                                 static_cast<PetscInt>(fluid.n_owned_vertices) * fluid.dim,
                                 PETSC_DETERMINE, fluid_work_.out()));
  collect();
}

void ImmersedConstraint::update_solid(const mesh::Mesh& moved) {
  solid_ = &moved;
  transfer_->update_master(moved);
  collect();
}

void ImmersedConstraint::restore(const mesh::Mesh& moved, std::vector<int> constrained,
                                 bool frozen) {
  constrained_ = std::move(constrained);
  frozen_ = true;
  update_solid(moved);
  frozen_ = frozen;
}

void ImmersedConstraint::collect() {
  // B ⊗ I_dim acts on interleaved vertex vectors; re-created because update_master may have
  // re-created B.
  COAPT_PETSC_CHECK(MatCreateMAIJ(transfer_->coupling(), fluid_.dim, coupling_.out()));
  std::vector<int> vertices;
  if (frozen_) {
    vertices = constrained_;
  } else {
    for (const PetscInt row : transfer_->constrained_rows()) {
      const auto v = static_cast<int>(row - fluid_.vertex_offset);
      if (v < 0 || v >= fluid_.n_owned_vertices || fluid_.global_vertex[v] != row)
        throw InternalError("immersed constraint: a constrained row is not an owned fluid vertex");
      vertices.push_back(v);
    }
  }
  constrained_.clear();
  dual_.clear();
  const PetscScalar* dual = nullptr;
  COAPT_PETSC_CHECK(VecGetArrayRead(transfer_->dual_mass(), &dual));
  for (const int v : vertices) {
    // no longer covered: T is not defined there (in a group: the summed D_i decides)
    if (frozen_ && !shared_ && !(dual[v] > 0.0)) continue;
    if (!fixed_.empty() && fixed_[static_cast<std::size_t>(v)]) continue;  // its own condition
    constrained_.push_back(v);
    dual_.push_back(dual[v]);
  }
  COAPT_PETSC_CHECK(VecRestoreArrayRead(transfer_->dual_mass(), &dual));
  own_dual_ = dual_;
  count_constrained();
  collect_partial();
}

void ImmersedConstraint::collect_partial() {
  partial_.clear();
  partial_weight_.clear();
  partial_integral_.clear();
  const double threshold = transfer_->options().coverage_threshold;
  if (partial_from_ < threshold) {
    COAPT_PETSC_CHECK(
        MatCreateMAIJ(transfer_->standard_coupling(), fluid_.dim, partial_coupling_.out()));
    constexpr double largest = 1e6;  // the weight of a node as good as constrained
    std::vector<char> member(static_cast<std::size_t>(fluid_.n_owned_vertices), 0);
    for (const int v : constrained_) member[static_cast<std::size_t>(v)] = 1;
    const PetscScalar *coverage = nullptr, *integral = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(transfer_->coverage(), &coverage));
    COAPT_PETSC_CHECK(VecGetArrayRead(transfer_->covered_integral(), &integral));
    for (int v = 0; v < fluid_.n_owned_vertices; ++v) {
      const auto index = static_cast<std::size_t>(v);
      if (member[index] || (!fixed_.empty() && fixed_[index])) continue;
      const double c = coverage[v];
      if (!(c > partial_from_) || !(integral[v] > 0.0)) continue;
      partial_.push_back(v);
      partial_weight_.push_back(
          c < threshold ? std::min(largest, (c - partial_from_) / (threshold - c)) : largest);
      partial_integral_.push_back(integral[v]);
    }
    COAPT_PETSC_CHECK(VecRestoreArrayRead(transfer_->covered_integral(), &integral));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(transfer_->coverage(), &coverage));
  }
  n_partial_ = global_count(partial_.size(), fluid_.comm);
}

void ImmersedConstraint::drop_partial(const std::vector<char>& member) {
  std::size_t kept = 0;
  for (std::size_t q = 0; q < partial_.size(); ++q) {
    if (member.at(static_cast<std::size_t>(partial_[q]))) continue;
    partial_[kept] = partial_[q];
    partial_weight_[kept] = partial_weight_[q];
    partial_integral_[kept] = partial_integral_[q];
    ++kept;
  }
  partial_.resize(kept);
  partial_weight_.resize(kept);
  partial_integral_.resize(kept);
  n_partial_ = global_count(kept, fluid_.comm);
}

std::vector<double> ImmersedConstraint::partial_velocity(Vec solid_velocity) const {
  if (!partial_coupling_) return {};
  return divided_product(partial_coupling_, solid_velocity, partial_, partial_integral_);
}

std::vector<double> ImmersedConstraint::partial_uniform_velocity(
    const std::vector<double>& velocity) const {
  const auto dim = static_cast<std::size_t>(fluid_.dim);
  if (velocity.size() != dim) throw InternalError("partial_uniform_velocity: needs dim components");
  // the weights B^std_ij / ∫_Ω λ_i sum to 1
  std::vector<double> velocities(partial_.size() * dim);
  for (std::size_t q = 0; q < partial_.size(); ++q)
    for (std::size_t i = 0; i < dim; ++i) velocities[q * dim + i] = velocity[i];
  return velocities;
}

void ImmersedConstraint::add_partial_force(const std::vector<double>& reactions,
                                           Vec solid_force) const {
  const int dim = fluid_.dim;
  if (reactions.size() != partial_.size() * dim)
    throw InternalError("immersed constraint: reactions must be partial vertices × dim");
  if (!partial_coupling_) return;
  std::vector<double> multiplier(reactions.size());
  for (std::size_t k = 0; k < reactions.size(); ++k)
    multiplier[k] = reactions[k] / partial_integral_[k / static_cast<std::size_t>(dim)];
  transpose_product(partial_coupling_, partial_, multiplier, solid_force, true);
}

std::vector<double> ImmersedConstraint::sum_partial(const std::vector<double>& values) const {
  const int dim = fluid_.dim;
  if (values.size() != partial_.size() * dim)
    throw InternalError("immersed constraint: values must be partial vertices × dim");
  std::vector<double> sum(static_cast<std::size_t>(dim), 0.0);
  for (std::size_t k = 0; k < values.size(); ++k) sum[k % dim] += values[k];
  MPI_Allreduce(MPI_IN_PLACE, sum.data(), dim, MPI_DOUBLE, MPI_SUM, fluid_.comm);
  return sum;
}

void ImmersedConstraint::assign(std::vector<int> vertices, std::vector<double> total_dual) {
  if (vertices.size() != total_dual.size())
    throw InternalError("immersed constraint: one summed D_i per constrained vertex");
  constrained_ = std::move(vertices);
  dual_ = std::move(total_dual);
  own_dual_.clear();
  const PetscScalar* dual = nullptr;
  COAPT_PETSC_CHECK(VecGetArrayRead(transfer_->dual_mass(), &dual));
  for (const int v : constrained_) own_dual_.push_back(dual[v]);
  COAPT_PETSC_CHECK(VecRestoreArrayRead(transfer_->dual_mass(), &dual));
  count_constrained();
}

void ImmersedConstraint::count_constrained() {
  n_constrained_ = global_count(constrained_.size(), fluid_.comm);
}

std::vector<double> ImmersedConstraint::transfer_velocity(Vec solid_velocity) const {
  return divided_product(coupling_, solid_velocity, constrained_, dual_);
}

std::vector<double> ImmersedConstraint::divided_product(Mat coupling, Vec solid_vector,
                                                        const std::vector<int>& vertices,
                                                        const std::vector<double>& divisors) const {
  const int dim = fluid_.dim;
  COAPT_PETSC_CHECK(MatMult(coupling, solid_vector, fluid_work_));
  std::vector<double> values(vertices.size() * dim);
  const PetscScalar* product = nullptr;
  COAPT_PETSC_CHECK(VecGetArrayRead(fluid_work_, &product));
  for (std::size_t q = 0; q < vertices.size(); ++q)
    for (int i = 0; i < dim; ++i)
      values[q * dim + i] = product[static_cast<std::size_t>(vertices[q]) * dim + i] / divisors[q];
  COAPT_PETSC_CHECK(VecRestoreArrayRead(fluid_work_, &product));
  return values;
}

std::vector<double> ImmersedConstraint::transfer_uniform_velocity(
    const std::vector<double>& velocity) const {
  const int dim = solid_->dim;
  if (static_cast<int>(velocity.size()) != dim)
    throw InternalError("transfer_uniform_velocity: needs dim components");
  auto solid_velocity = create_solid_vector();
  PetscScalar* values = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(solid_velocity, &values));
  for (int v = 0; v < solid_->n_owned_vertices; ++v)
    for (int i = 0; i < dim; ++i) values[static_cast<std::size_t>(v) * dim + i] = velocity[i];
  COAPT_PETSC_CHECK(VecRestoreArray(solid_velocity, &values));
  return transfer_velocity(solid_velocity);
}

std::vector<double> ImmersedConstraint::multiplier(const std::vector<double>& reactions) const {
  const int dim = fluid_.dim;
  if (reactions.size() != constrained_.size() * dim)
    throw InternalError("immersed constraint: reactions must be constrained vertices × dim");
  std::vector<double> lambda(reactions.size());
  for (std::size_t q = 0; q < constrained_.size(); ++q)
    for (int i = 0; i < dim; ++i) lambda[q * dim + i] = reactions[q * dim + i] / dual_[q];
  return lambda;
}

void ImmersedConstraint::solid_force(const std::vector<double>& multiplier, Vec solid_force) const {
  if (multiplier.size() != constrained_.size() * fluid_.dim)
    throw InternalError("immersed constraint: multiplier must be constrained vertices × dim");
  transpose_product(coupling_, constrained_, multiplier, solid_force, false);
}

void ImmersedConstraint::transpose_product(Mat coupling, const std::vector<int>& vertices,
                                           const std::vector<double>& values, Vec solid_vector,
                                           bool add) const {
  const int dim = fluid_.dim;
  COAPT_PETSC_CHECK(VecSet(fluid_work_, 0.0));
  PetscScalar* work = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(fluid_work_, &work));
  for (std::size_t q = 0; q < vertices.size(); ++q)
    for (int i = 0; i < dim; ++i)
      work[static_cast<std::size_t>(vertices[q]) * dim + i] = values[q * dim + i];
  COAPT_PETSC_CHECK(VecRestoreArray(fluid_work_, &work));
  if (add)
    COAPT_PETSC_CHECK(MatMultTransposeAdd(coupling, fluid_work_, solid_vector, solid_vector));
  else
    COAPT_PETSC_CHECK(MatMultTranspose(coupling, fluid_work_, solid_vector));
}

OwnedVec ImmersedConstraint::create_solid_vector() const {
  return fem::create_vertex_vector(*solid_, solid_->dim);
}

std::vector<double> ImmersedConstraint::sum_components(Vec solid_vector) const {
  const int dim = solid_->dim;
  std::vector<double> sum(static_cast<std::size_t>(dim), 0.0);
  const PetscScalar* values = nullptr;
  PetscInt n = 0;
  COAPT_PETSC_CHECK(VecGetLocalSize(solid_vector, &n));
  COAPT_PETSC_CHECK(VecGetArrayRead(solid_vector, &values));
  for (PetscInt k = 0; k < n; ++k) sum[static_cast<std::size_t>(k % dim)] += values[k];
  COAPT_PETSC_CHECK(VecRestoreArrayRead(solid_vector, &values));
  MPI_Allreduce(MPI_IN_PLACE, sum.data(), dim, MPI_DOUBLE, MPI_SUM, solid_->comm);
  return sum;
}

void ImmersedConstraint::solid_pressure(Vec fluid_state, Vec pressure) const {
  const Mat coupling = transfer_->standard_coupling();
  if (!coupling) throw InternalError("solid_pressure: the transfer has no standard coupling");
  OwnedVec on_solid, weight, on_fluid;
  COAPT_PETSC_CHECK(MatCreateVecs(coupling, on_solid.out(), on_fluid.out()));
  COAPT_PETSC_CHECK(VecDuplicate(on_solid, weight.out()));
  {
    const int n = fluid_.dim + 1;
    const PetscScalar* state = nullptr;
    PetscScalar* values = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(fluid_state, &state));
    COAPT_PETSC_CHECK(VecGetArray(on_fluid, &values));
    for (int v = 0; v < fluid_.n_owned_vertices; ++v)
      values[v] = state[static_cast<std::size_t>(v) * n + fluid_.dim];
    COAPT_PETSC_CHECK(VecRestoreArray(on_fluid, &values));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(fluid_state, &state));
  }
  COAPT_PETSC_CHECK(MatMultTranspose(coupling, on_fluid, on_solid));
  COAPT_PETSC_CHECK(VecSet(on_fluid, 1.0));
  COAPT_PETSC_CHECK(MatMultTranspose(coupling, on_fluid, weight));
  {
    const PetscScalar *sum = nullptr, *total = nullptr;
    PetscScalar* values = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(on_solid, &sum));
    COAPT_PETSC_CHECK(VecGetArrayRead(weight, &total));
    COAPT_PETSC_CHECK(VecGetArray(pressure, &values));
    for (int v = 0; v < solid_->n_owned_vertices; ++v)
      values[v] = total[v] > 0.0 ? sum[v] / total[v] : 0.0;
    COAPT_PETSC_CHECK(VecRestoreArray(pressure, &values));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(weight, &total));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(on_solid, &sum));
  }
  fem::update_ghosts(pressure);
}

std::vector<double> ImmersedConstraint::sum_constrained(const std::vector<double>& values) const {
  const int dim = fluid_.dim;
  if (values.size() != constrained_.size() * dim)
    throw InternalError("immersed constraint: values must be constrained vertices × dim");
  std::vector<double> sum(static_cast<std::size_t>(dim), 0.0);
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::size_t q = k / static_cast<std::size_t>(dim);
    // x · (D_k,i / D_i) is x itself when the node is not shared (D_k,i = D_i)
    sum[k % dim] += own_dual_[q] == dual_[q] ? values[k] : values[k] * own_dual_[q] / dual_[q];
  }
  MPI_Allreduce(MPI_IN_PLACE, sum.data(), dim, MPI_DOUBLE, MPI_SUM, fluid_.comm);
  return sum;
}

}  // namespace coapt::coupling
