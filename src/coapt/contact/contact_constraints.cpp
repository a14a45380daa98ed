// The contact transformation of the solid's Newton system (contact_constraints.hpp): surfaces
// gathered on every rank, mortar operators and multipliers at each residual, the active set,
// and the row operator P and gap rows G assembled row by row on their owning ranks.
#include "coapt/contact/contact_constraints.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "coapt/core/error.hpp"

namespace coapt::contact {

namespace {

/// A sparse matrix of the dof layout [first, end) on each rank from owned-row triplets.
OwnedMat matrix_from_triplets(MPI_Comm comm, PetscInt n_local, std::vector<PetscInt>& rows,
                              std::vector<PetscInt>& columns, const std::vector<double>& values) {
  OwnedMat matrix;
  COAPT_PETSC_CHECK(MatCreate(comm, matrix.out()));
  COAPT_PETSC_CHECK(MatSetSizes(matrix, n_local, n_local, PETSC_DETERMINE, PETSC_DETERMINE));
  // MPIAIJ on every communicator size, like the solid's P1Matrix (products need one type).
  COAPT_PETSC_CHECK(MatSetType(matrix, MATMPIAIJ));
  COAPT_PETSC_CHECK(MatSetPreallocationCOO(matrix, static_cast<PetscCount>(rows.size()),
                                           rows.data(), columns.data()));
  COAPT_PETSC_CHECK(MatSetValuesCOO(matrix, values.data(), INSERT_VALUES));
  return matrix;
}

}  // namespace

ContactConstraints::ContactConstraints(const ContactParameters& parameters, const mesh::Mesh& mesh,
                                       std::span<const PetscInt> dirichlet_dofs, Vec layout)
    : parameters_(parameters),
      mesh_(mesh),
      dim_(mesh.dim),
      dirichlet_(dirichlet_dofs.begin(), dirichlet_dofs.end()) {
  std::sort(dirichlet_.begin(), dirichlet_.end());
  first_dof_ = mesh.vertex_offset * dim_;
  end_dof_ = first_dof_ + static_cast<PetscInt>(mesh.n_owned_vertices) * dim_;
  complementarity_constant_ = parameters.complementarity_constant;
  COAPT_PETSC_CHECK(VecDuplicate(layout, dirichlet_marker_.out()));
  COAPT_PETSC_CHECK(VecDuplicate(layout, work_.out()));
  COAPT_PETSC_CHECK(VecSet(dirichlet_marker_, 0.0));
  for (PetscInt dof : dirichlet_)
    COAPT_PETSC_CHECK(VecSetValue(dirichlet_marker_, dof, 1.0, INSERT_VALUES));
  COAPT_PETSC_CHECK(VecAssemblyBegin(dirichlet_marker_));
  COAPT_PETSC_CHECK(VecAssemblyEnd(dirichlet_marker_));

  const auto boundary_tag = [&](const std::string& name, const std::string& where) {
    const auto* group = mesh.find_group(name);
    if (!group || group->dim != dim_ - 1) {
      std::string names;
      for (const auto& g : mesh.groups)
        if (g.dim == dim_ - 1) names += (names.empty() ? "" : ", ") + g.name;
      throw InputError(fmt::format("{}: no boundary group '{}' in {} (it has: {})", where, name,
                                   mesh.source, names.empty() ? "none" : names));
    }
    return group->tag;
  };
  std::vector<PetscInt> slave_vertices;
  for (const auto& pair : parameters.pairs) {
    const int slave_tag = boundary_tag(pair.slave, pair.where);
    const int master_tag = boundary_tag(pair.master, pair.where);
    PairState state;
    state.slave = gather_surface(mesh, std::span<const int>(&slave_tag, 1), pair.slave);
    state.master = gather_surface(mesh, std::span<const int>(&master_tag, 1), pair.master);
    if (state.slave.n_facets() == 0 || state.master.n_facets() == 0)
      throw InputError(fmt::format("{}: boundary group '{}' has no facets in {}", pair.where,
                                   state.slave.n_facets() == 0 ? pair.slave : pair.master,
                                   mesh.source));
    slave_vertices.insert(slave_vertices.end(), state.slave.global_vertex.begin(),
                          state.slave.global_vertex.end());
    slave_gathers_.push_back(std::make_unique<SurfaceGather>(state.slave, layout));
    master_gathers_.push_back(std::make_unique<SurfaceGather>(state.master, layout));
    std::vector<double> marker;
    slave_gathers_.back()->gather(dirichlet_marker_, marker);
    state.dirichlet.assign(marker.size(), 0);
    for (std::size_t k = 0; k < marker.size(); ++k) state.dirichlet[k] = marker[k] > 0.5;
    master_gathers_.back()->gather(dirichlet_marker_, marker);
    state.master_dirichlet.assign(marker.size(), 0);
    for (std::size_t k = 0; k < marker.size(); ++k) state.master_dirichlet[k] = marker[k] > 0.5;
    double size = 0;
    for (int f = 0; f < state.slave.n_facets(); ++f) {
      const auto a = facet_area_normal(state.slave, state.slave.reference, f);
      const double measure = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
      size += dim_ == 2 ? measure : std::sqrt(4.0 * measure / std::sqrt(3.0));
    }
    reference_sizes_.push_back(size / state.slave.n_facets());
    const std::size_t n = static_cast<std::size_t>(state.slave.n_nodes());
    state.pressure.assign(n, 0.0);
    state.active.assign(n, 0);
    pairs_.push_back(std::move(state));
  }
  std::sort(slave_vertices.begin(), slave_vertices.end());
  if (std::adjacent_find(slave_vertices.begin(), slave_vertices.end()) != slave_vertices.end())
    throw InputError(
        fmt::format("{}: pairs: a node belongs to the slave surfaces of two pairs "
                    "(give each slave surface one pair)",
                    parameters.where));
}

ContactConstraints::~ContactConstraints() = default;

void ContactConstraints::update(Vec u, Vec residual) {
  ContactStatus status;
  status.complementarity_constant = complementarity_constant_;
  status.min_active_pressure = 0.0;
  bool first_active = true;
  std::vector<double> force;
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    auto& pair = pairs_[p];
    current_positions(p, u, pair.slave_x, pair.master_x);
    slave_gathers_[p]->gather(residual, force);
    pair.slave_residual = force;
    pair.mortar =
        assemble_mortar(pair.slave, pair.slave_x, pair.master, pair.master_x, mortar_options(p));
    const double tolerance = parameters_.relative_gap_tolerance * reference_sizes_[p];
    status.gap_tolerance = std::max(status.gap_tolerance, tolerance);
    const auto& m = pair.mortar;
    std::vector<double> row_sum(static_cast<std::size_t>(pair.slave.n_nodes()), 0.0);
    for (const auto& e : m.slave_coupling) row_sum[e.row] += e.value;  // ∫_Γc Φ̃_j
    for (int j = 0; j < pair.slave.n_nodes(); ++j) {
      const bool was_active = pair.active[j] != 0;
      pair.pressure[j] = 0.0;
      pair.active[j] = 0;
      if (!m.constrained(j)) {
        status.changes += was_active ? 1 : 0;
        continue;
      }
      ++status.constrained;
      double normal_force = 0.0;  // n_j · R_j over the free components
      for (int i = 0; i < dim_; ++i) {
        const std::size_t k = static_cast<std::size_t>(j) * dim_ + i;
        if (!pair.dirichlet[k]) normal_force += m.normals[k] * force[k];
      }
      const double pressure = -normal_force / m.dual_mass[j];
      const double gap = m.gap(j);
      // An active node's own open gap does not count against it: with the frozen geometry the
      // step that closes a gap leaves a small positive one behind, and c times it (c from the
      // stiffness) can outweigh the node's pressure, releasing a node in compression and
      // cycling. Such a node leaves when its pressure is tensile
      // beyond c times any penetration. At convergence the gap rows hold g_j = 0 on A, so the
      // converged set satisfies the same conditions as with the plain test.
      const double open_gap = was_active ? std::min(gap - tolerance, 0.0) : gap - tolerance;
      const bool active = complementarity_constant_ > 0.0
                              ? pressure - complementarity_constant_ * open_gap > 0.0
                              : gap <= tolerance;
      pair.pressure[j] = pressure;
      pair.active[j] = active;
      if (active != was_active && ++status.changes <= 4)
        status.changed_nodes += fmt::format("{}{}:{} {} (p {:.3e} Pa, g {:.3e} m)",
                                            status.changed_nodes.empty() ? "" : ", ", p, j,
                                            active ? "in" : "out", pressure, gap);
      status.max_penetration = std::max(status.max_penetration, -gap);
      status.max_complementarity = std::max(status.max_complementarity, std::abs(pressure * gap));
      if (active) {
        ++status.active;
        status.max_pressure = std::max(status.max_pressure, pressure);
        status.min_active_pressure =
            first_active ? pressure : std::min(status.min_active_pressure, pressure);
        first_active = false;
        status.total_force += row_sum[j] * pressure;
        for (int i = 0; i < dim_; ++i)
          status.force_vector[static_cast<std::size_t>(i)] +=
              row_sum[j] * pressure * m.normals[static_cast<std::size_t>(j) * dim_ + i];
        status.contact_measure += row_sum[j];
      } else {
        status.max_open_pressure = std::max(status.max_open_pressure, std::abs(pressure));
      }
    }
  }
  status_ = status;
  build_row_operator();
  if (status_.active == 0) return;
  // R ← P R − c n g̃ on the active rows.
  COAPT_PETSC_CHECK(MatMult(row_operator_, residual, work_));
  add_gap_terms(work_, -1.0);
  COAPT_PETSC_CHECK(VecCopy(work_, residual));
}

bool ContactConstraints::prescribed(PetscInt dof) const {
  return std::binary_search(dirichlet_.begin(), dirichlet_.end(), dof);
}

void ContactConstraints::add_gap_terms(Vec v, double sign) {
  for (const auto& pair : pairs_)
    for (int j = 0; j < pair.slave.n_nodes(); ++j) {
      if (!pair.active[j]) continue;
      for (int i = 0; i < dim_; ++i) {
        const PetscInt dof = pair.slave.global_vertex[j] * dim_ + i;
        if (dof < first_dof_ || dof >= end_dof_ ||
            pair.dirichlet[static_cast<std::size_t>(j) * dim_ + i])
          continue;
        const double value = sign * complementarity_constant_ *
                             pair.mortar.normals[static_cast<std::size_t>(j) * dim_ + i] *
                             pair.mortar.weighted_gap[j];
        COAPT_PETSC_CHECK(VecSetValue(v, dof, value, ADD_VALUES));
      }
    }
  COAPT_PETSC_CHECK(VecAssemblyBegin(v));
  COAPT_PETSC_CHECK(VecAssemblyEnd(v));
}

void ContactConstraints::active_marker(std::size_t p, Vec marker) const {
  COAPT_PETSC_CHECK(VecSet(marker, 0.0));
  const auto& pair = pairs_[p];
  PetscScalar* values = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(marker, &values));
  for (int j = 0; j < pair.slave.n_nodes(); ++j) {
    const PetscInt first = pair.slave.global_vertex[j] * dim_;
    if (!pair.active[j] || first < first_dof_ || first >= end_dof_) continue;
    for (int i = 0; i < dim_; ++i) values[first - first_dof_ + i] = 1.0;
  }
  COAPT_PETSC_CHECK(VecRestoreArray(marker, &values));
}

void ContactConstraints::restore_active(std::size_t p, Vec marker) {
  std::vector<double> values;
  slave_gathers_[p]->gather(marker, values);
  auto& pair = pairs_[p];
  for (int j = 0; j < pair.slave.n_nodes(); ++j)
    pair.active[j] = values[static_cast<std::size_t>(j) * dim_] > 0.5 ? 1 : 0;
}

ContactConstraints::Snapshot ContactConstraints::snapshot() const {
  Snapshot snapshot;
  snapshot.pairs.reserve(pairs_.size());
  for (const auto& pair : pairs_) {
    PairState state;
    state.slave_x = pair.slave_x;
    state.master_x = pair.master_x;
    state.mortar = pair.mortar;
    state.pressure = pair.pressure;
    state.active = pair.active;
    state.slave_residual = pair.slave_residual;
    snapshot.pairs.push_back(std::move(state));
  }
  snapshot.status = status_;
  snapshot.complementarity_constant = complementarity_constant_;
  return snapshot;
}

void ContactConstraints::restore(const Snapshot& snapshot) {
  if (snapshot.pairs.size() != pairs_.size())
    throw InternalError("ContactConstraints::restore: a snapshot of other pairs");
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    const auto& state = snapshot.pairs[p];
    auto& pair = pairs_[p];
    pair.slave_x = state.slave_x;
    pair.master_x = state.master_x;
    pair.mortar = state.mortar;
    pair.pressure = state.pressure;
    pair.active = state.active;
    pair.slave_residual = state.slave_residual;
  }
  status_ = snapshot.status;
  complementarity_constant_ = snapshot.complementarity_constant;
}

void ContactConstraints::current_positions(std::size_t p, Vec u, std::vector<double>& slave_x,
                                           std::vector<double>& master_x) const {
  const auto& pair = pairs_[p];
  std::vector<double> displacement;
  slave_gathers_[p]->gather(u, displacement);
  slave_x = pair.slave.reference;
  for (std::size_t k = 0; k < slave_x.size(); ++k) slave_x[k] += displacement[k];
  master_gathers_[p]->gather(u, displacement);
  master_x = pair.master.reference;
  for (std::size_t k = 0; k < master_x.size(); ++k) master_x[k] += displacement[k];
}

MortarOptions ContactConstraints::mortar_options(std::size_t p) const {
  MortarOptions options;
  options.search_distance =
      parameters_.search_distance > 0.0 ? parameters_.search_distance : 10.0 * reference_sizes_[p];
  options.coverage_threshold = parameters_.coverage_threshold;
  options.boundary_modification = parameters_.boundary_modification;
  options.fixed_components = pairs_[p].dirichlet;
  return options;
}

int ContactConstraints::project_predictor(Vec u, Vec increment, Vec lumped_mass) {
  // The predictor uₙ + δ projected onto the admissible set in the lumped-mass norm
  // (Deuflhard, Krause, Ertel 2008; method/notes.md): min ½ Σ_i m_i (δ_i − δ̂_i)² subject to
  // the linearised weighted gaps
  //   G_j(δ) = g̃_j + n_j · (Σ_l M_jl δ_l − Σ_k D̂_jk δ_k) ≥ 0
  // of the constrained slave nodes (mortar operators at u = uₙ). With a held master (the
  // master's mass infinite) every constraint moves its own slave node only and the
  // projection is the node-wise clip of the normal component. With two deformable bodies the
  // gaps couple slave and master nodes: the quadratic program is solved by projected
  // Gauss–Seidel on its multipliers μ_j ≥ 0, δ = δ̂ + M⁻¹ Σ_j μ_j a_j with a_j = ∂G_j/∂δ
  // (−D̂_jk n_j on slave nodes, M_jl n_j on master nodes). Its correction conserves linear
  // momentum (Σ_i m_i Δδ_i = Σ_j μ_j (Σ_l M_jl − Σ_k D̂_jk) n_j = 0 on covered nodes), where a
  // clip of the slave alone would not. Prescribed components do not move (infinite mass).
  constexpr int kMaxSweeps = 200;
  int projected_nodes = 0;
  std::vector<double> slave_increment, master_increment, slave_mass, master_mass;
  for (std::size_t p = 0; p < pairs_.size(); ++p) {
    const auto& pair = pairs_[p];
    std::vector<double> slave_x, master_x;
    current_positions(p, u, slave_x, master_x);
    slave_gathers_[p]->gather(increment, slave_increment);
    master_gathers_[p]->gather(increment, master_increment);
    slave_gathers_[p]->gather(lumped_mass, slave_mass);
    master_gathers_[p]->gather(lumped_mass, master_mass);
    const auto m = assemble_mortar(pair.slave, slave_x, pair.master, master_x, mortar_options(p));
    // 1/m per dof (0 where prescribed or massless).
    const auto inverse = [](const std::vector<double>& mass, const std::vector<char>& fixed) {
      std::vector<double> result(mass.size(), 0.0);
      for (std::size_t k = 0; k < mass.size(); ++k)
        if (!fixed[k] && mass[k] > 0.0) result[k] = 1.0 / mass[k];
      return result;
    };
    const auto slave_inverse = inverse(slave_mass, pair.dirichlet);
    const auto master_inverse = inverse(master_mass, pair.master_dirichlet);
    // The constraints' entries by row (slave_coupling and master_coupling are sorted by row).
    struct Term {
      bool master;
      int node;
      double coefficient;  // of n_j in a_j
    };
    std::vector<std::vector<Term>> rows(static_cast<std::size_t>(pair.slave.n_nodes()));
    for (const auto& e : m.slave_coupling)
      if (m.constrained(e.row)) rows[e.row].push_back({false, e.column, -e.value});
    for (const auto& e : m.master_coupling)
      if (m.constrained(e.row)) rows[e.row].push_back({true, e.column, e.value});
    std::vector<double> weight(rows.size(), 0.0), multiplier(rows.size(), 0.0);
    for (std::size_t j = 0; j < rows.size(); ++j) {
      const double* n = m.normals.data() + j * dim_;
      for (const auto& t : rows[j])
        for (int i = 0; i < dim_; ++i) {
          const std::size_t k = static_cast<std::size_t>(t.node) * dim_ + i;
          const double w = t.master ? master_inverse[k] : slave_inverse[k];
          weight[j] += t.coefficient * t.coefficient * n[i] * n[i] * w;
        }
    }
    const auto gap = [&](std::size_t j) {
      const double* n = m.normals.data() + j * dim_;
      double g = m.weighted_gap[j];
      for (const auto& t : rows[j])
        for (int i = 0; i < dim_; ++i) {
          const std::size_t k = static_cast<std::size_t>(t.node) * dim_ + i;
          g += t.coefficient * n[i] * (t.master ? master_increment[k] : slave_increment[k]);
        }
      return g;
    };
    double scale = 0.0;  // the largest |G_j(δ̂)|, for the stopping test
    for (std::size_t j = 0; j < rows.size(); ++j)
      if (!rows[j].empty())
        scale = std::max({scale, std::abs(m.weighted_gap[j]), std::abs(gap(j))});
    for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
      double largest = 0.0;
      for (std::size_t j = 0; j < rows.size(); ++j) {
        if (rows[j].empty() || !(weight[j] > 0.0)) continue;
        const double step = std::max(-multiplier[j], -gap(j) / weight[j]);
        if (step == 0.0) continue;
        multiplier[j] += step;
        const double* n = m.normals.data() + j * dim_;
        for (const auto& t : rows[j])
          for (int i = 0; i < dim_; ++i) {
            const std::size_t k = static_cast<std::size_t>(t.node) * dim_ + i;
            if (t.master)
              master_increment[k] += step * t.coefficient * n[i] * master_inverse[k];
            else
              slave_increment[k] += step * t.coefficient * n[i] * slave_inverse[k];
          }
        largest = std::max(largest, std::abs(step) * weight[j]);
      }
      if (largest <= 1e-12 * scale) break;
    }
    for (std::size_t j = 0; j < rows.size(); ++j) projected_nodes += multiplier[j] > 0.0 ? 1 : 0;
    // Each rank writes its owned entries of the (identical) result.
    const auto write = [&](const Surface& surface, const std::vector<double>& values) {
      for (int node = 0; node < surface.n_nodes(); ++node)
        for (int i = 0; i < dim_; ++i) {
          const PetscInt dof = surface.global_vertex[node] * dim_ + i;
          if (dof < first_dof_ || dof >= end_dof_) continue;
          COAPT_PETSC_CHECK(VecSetValue(
              increment, dof, values[static_cast<std::size_t>(node) * dim_ + i], INSERT_VALUES));
        }
    };
    write(pair.slave, slave_increment);
    write(pair.master, master_increment);
    COAPT_PETSC_CHECK(VecAssemblyBegin(increment));
    COAPT_PETSC_CHECK(VecAssemblyEnd(increment));
  }
  return projected_nodes;
}

void ContactConstraints::build_row_operator() {
  row_operator_.reset();
  if (status_.active == 0) return;
  // Normals of the active slave nodes by global vertex (for S_k on rows that are active too).
  std::unordered_map<PetscInt, const double*> active_normal;
  for (const auto& pair : pairs_)
    for (int j = 0; j < pair.slave.n_nodes(); ++j)
      if (pair.active[j])
        active_normal[pair.slave.global_vertex[j]] =
            pair.mortar.normals.data() + static_cast<std::size_t>(j) * dim_;
  std::vector<PetscInt> rows, columns;
  std::vector<double> values;
  for (PetscInt dof = first_dof_; dof < end_dof_; ++dof) {
    rows.push_back(dof);
    columns.push_back(dof);
    values.push_back(1.0);
  }
  // Adds coefficient × S_row n nᵀ into block (row vertex, column vertex), owned free rows only.
  const auto add_block = [&](PetscInt row_vertex, PetscInt column_vertex, const double* n,
                             double coefficient, const std::vector<char>& column_dirichlet,
                             int column_node) {
    const auto found = active_normal.find(row_vertex);
    const double* s = found == active_normal.end() ? nullptr : found->second;
    for (int a = 0; a < dim_; ++a) {
      const PetscInt row = row_vertex * dim_ + a;
      if (row < first_dof_ || row >= end_dof_ || prescribed(row)) continue;
      // (S n)_a = n_a − s_a (s · n) when the row node is active.
      double sn = n[a];
      if (s) {
        double sdotn = 0.0;
        for (int i = 0; i < dim_; ++i) sdotn += s[i] * n[i];
        sn -= s[a] * sdotn;
      }
      if (sn == 0.0) continue;
      for (int b = 0; b < dim_; ++b) {
        if (column_dirichlet[static_cast<std::size_t>(column_node) * dim_ + b]) continue;
        rows.push_back(row);
        columns.push_back(column_vertex * dim_ + b);
        values.push_back(coefficient * sn * n[b]);
      }
    }
  };
  for (const auto& pair : pairs_) {
    const auto& m = pair.mortar;
    for (int j = 0; j < pair.slave.n_nodes(); ++j) {
      if (!pair.active[j]) continue;
      const double* n = m.normals.data() + static_cast<std::size_t>(j) * dim_;
      const PetscInt vertex = pair.slave.global_vertex[j];
      // −n nᵀ on the node's own rows (S_j applied to the identity row block: I − n nᵀ).
      for (int a = 0; a < dim_; ++a) {
        const PetscInt row = vertex * dim_ + a;
        if (row < first_dof_ || row >= end_dof_ || prescribed(row)) continue;
        for (int b = 0; b < dim_; ++b) {
          if (pair.dirichlet[static_cast<std::size_t>(j) * dim_ + b]) continue;
          rows.push_back(row);
          columns.push_back(vertex * dim_ + b);
          values.push_back(-n[a] * n[b]);
        }
      }
    }
    // Elimination of λ_j from the other rows: −B_jk / D_jj (S_k n_j n_jᵀ) in block (k, j).
    for (const auto& e : m.master_coupling)
      if (pair.active[e.row])
        add_block(pair.master.global_vertex[e.column], pair.slave.global_vertex[e.row],
                  m.normals.data() + static_cast<std::size_t>(e.row) * dim_,
                  e.value / m.dual_mass[e.row], pair.dirichlet, e.row);
    for (const auto& e : m.slave_coupling)
      if (pair.active[e.row] && e.column != e.row)
        add_block(pair.slave.global_vertex[e.column], pair.slave.global_vertex[e.row],
                  m.normals.data() + static_cast<std::size_t>(e.row) * dim_,
                  -e.value / m.dual_mass[e.row], pair.dirichlet, e.row);
  }
  row_operator_ = matrix_from_triplets(mesh_.comm, end_dof_ - first_dof_, rows, columns, values);
}

Mat ContactConstraints::transform(Mat K, Vec rhs) {
  // c is taken as soon as a slave node is constrained, active or not: the active-set test of
  // the next update needs it (contact_constraints.hpp, update).
  if (!(complementarity_constant_ > 0.0) && status_.constrained > 0) {
    // c from the stiffness: mean K_ii over the free dofs of constrained slave nodes over the
    // mean D_jj of those nodes, so the gap rows weigh like the equilibrium rows.
    OwnedVec diagonal;
    COAPT_PETSC_CHECK(VecDuplicate(work_, diagonal.out()));
    COAPT_PETSC_CHECK(MatGetDiagonal(K, diagonal));
    double stiffness = 0.0, dual = 0.0;
    long n_dofs = 0, n_nodes = 0;
    std::vector<double> values;
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      slave_gathers_[p]->gather(diagonal, values);
      const auto& pair = pairs_[p];
      for (int j = 0; j < pair.slave.n_nodes(); ++j) {
        if (!pair.mortar.constrained(j)) continue;
        dual += pair.mortar.dual_mass[j];
        ++n_nodes;
        for (int i = 0; i < dim_; ++i) {
          const std::size_t k = static_cast<std::size_t>(j) * dim_ + i;
          if (pair.dirichlet[k]) continue;
          stiffness += std::abs(values[k]);
          ++n_dofs;
        }
      }
    }
    if (n_dofs > 0 && dual > 0.0)
      complementarity_constant_ = (stiffness / n_dofs) / (dual / n_nodes);
    status_.complementarity_constant = complementarity_constant_;
  }
  if (status_.active == 0) return K;
  // G = c Σ_{j∈A} E_j n_j n_jᵀ B_j on owned free rows (frozen geometry), or the derivative of
  // the whole geometry-dependent part (finite_difference, add_geometric_tangent).
  std::vector<PetscInt> rows, columns;
  std::vector<double> values;
  const double c = complementarity_constant_;
  // The derivative is taken once the active set holds (no node changed at this update): while
  // it is still being found, R is far from the contact forces it will balance and (dP/du) R
  // points the search astray.
  const bool geometric = parameters_.finite_difference_geometry && status_.changes == 0;
  for (std::size_t p = 0; p < pairs_.size() && geometric; ++p)
    add_geometric_tangent(p, rows, columns, values);
  for (const auto& pair : pairs_) {
    if (geometric) break;
    const auto& m = pair.mortar;
    const auto add_row_block = [&](const MortarEntry& e, PetscInt column_vertex, double sign) {
      const double* n = m.normals.data() + static_cast<std::size_t>(e.row) * dim_;
      const PetscInt vertex = pair.slave.global_vertex[e.row];
      for (int a = 0; a < dim_; ++a) {
        const PetscInt row = vertex * dim_ + a;
        if (row < first_dof_ || row >= end_dof_ || prescribed(row) || n[a] == 0.0) continue;
        for (int b = 0; b < dim_; ++b) {
          rows.push_back(row);
          columns.push_back(column_vertex * dim_ + b);
          values.push_back(sign * c * n[a] * n[b] * e.value);
        }
      }
    };
    for (const auto& e : m.slave_coupling)
      if (pair.active[e.row]) add_row_block(e, pair.slave.global_vertex[e.column], 1.0);
    for (const auto& e : m.master_coupling)
      if (pair.active[e.row]) add_row_block(e, pair.master.global_vertex[e.column], -1.0);
  }
  gap_rows_ = matrix_from_triplets(mesh_.comm, end_dof_ - first_dof_, rows, columns, values);
  contact_matrix_.reset();
  COAPT_PETSC_CHECK(
      MatMatMult(row_operator_, K, MAT_INITIAL_MATRIX, PETSC_DEFAULT, contact_matrix_.out()));
  COAPT_PETSC_CHECK(MatAXPY(contact_matrix_, 1.0, gap_rows_, DIFFERENT_NONZERO_PATTERN));
  // rhs = −(P R − c n g̃) from update(), plus whatever the caller added after it (the lifting
  // −K d of prescribed increments), which P has not seen. P is idempotent, but it does not
  // annihilate c n g̃: its elimination part carries the normal rows of A onto the master rows
  // (and other slave rows) as forces (M_jl / D_jj) c g̃_j n_j, which would push the master on
  // by the slave's penetration. So the gap terms are taken out before P and put back after:
  // rhs ← P (rhs − c n g̃) + c n g̃.
  add_gap_terms(rhs, -1.0);
  COAPT_PETSC_CHECK(MatMult(row_operator_, rhs, work_));
  add_gap_terms(work_, 1.0);
  COAPT_PETSC_CHECK(VecCopy(work_, rhs));
  return contact_matrix_;
}

void ContactConstraints::contact_terms(std::size_t p, std::span<const double> slave_x,
                                       std::span<const double> master_x,
                                       std::vector<double>& slave_terms,
                                       std::vector<double>& master_terms) const {
  const auto& pair = pairs_[p];
  const auto m = assemble_mortar(pair.slave, slave_x, pair.master, master_x, mortar_options(p));
  slave_terms.assign(slave_x.size(), 0.0);
  master_terms.assign(master_x.size(), 0.0);
  const double c = complementarity_constant_;
  std::vector<double> row_normal_force(static_cast<std::size_t>(pair.slave.n_nodes()), 0.0);
  for (int j = 0; j < pair.slave.n_nodes(); ++j) {
    if (!pair.active[j] || !(m.dual_mass[j] > 0.0)) continue;
    const double* n = m.normals.data() + static_cast<std::size_t>(j) * dim_;
    double q = 0.0;  // n_j · R_j over the free components
    for (int i = 0; i < dim_; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * dim_ + i;
      if (!pair.dirichlet[k]) q += n[i] * pair.slave_residual[k];
    }
    row_normal_force[static_cast<std::size_t>(j)] = q;
    for (int i = 0; i < dim_; ++i)
      slave_terms[static_cast<std::size_t>(j) * dim_ + i] -= n[i] * (q + c * m.weighted_gap[j]);
  }
  // (S_k n_j)_a with S_k = I − n_k n_kᵀ when slave node k is active.
  const auto projected = [&](int k, const double* n, int a) {
    if (!pair.active[k]) return n[a];
    const double* s = m.normals.data() + static_cast<std::size_t>(k) * dim_;
    double sn = 0.0;
    for (int i = 0; i < dim_; ++i) sn += s[i] * n[i];
    return n[a] - s[a] * sn;
  };
  for (const auto& e : m.slave_coupling) {
    if (!pair.active[e.row] || e.column == e.row || !(m.dual_mass[e.row] > 0.0)) continue;
    const double* n = m.normals.data() + static_cast<std::size_t>(e.row) * dim_;
    const double f = -e.value / m.dual_mass[e.row] * row_normal_force[e.row];
    for (int a = 0; a < dim_; ++a)
      slave_terms[static_cast<std::size_t>(e.column) * dim_ + a] += f * projected(e.column, n, a);
  }
  for (const auto& e : m.master_coupling) {
    if (!pair.active[e.row] || !(m.dual_mass[e.row] > 0.0)) continue;
    const double* n = m.normals.data() + static_cast<std::size_t>(e.row) * dim_;
    const double f = e.value / m.dual_mass[e.row] * row_normal_force[e.row];
    for (int a = 0; a < dim_; ++a)
      master_terms[static_cast<std::size_t>(e.column) * dim_ + a] += f * n[a];
  }
}

void ContactConstraints::add_geometric_tangent(std::size_t p, std::vector<PetscInt>& rows,
                                               std::vector<PetscInt>& columns,
                                               std::vector<double>& values) const {
  const auto& pair = pairs_[p];
  const auto& m = pair.mortar;
  // The nodes whose positions the terms depend on: the slave facets around the active nodes
  // and their coupled slave nodes (normals, dual basis, projections), the coupled master nodes.
  std::vector<char> slave_moves(static_cast<std::size_t>(pair.slave.n_nodes()), 0);
  std::vector<char> master_moves(static_cast<std::size_t>(pair.master.n_nodes()), 0);
  for (const auto& e : m.slave_coupling)
    if (pair.active[e.row]) slave_moves[e.column] = 1;
  for (const auto& e : m.master_coupling)
    if (pair.active[e.row]) master_moves[e.column] = 1;
  std::vector<char> around(slave_moves);
  for (int f = 0; f < pair.slave.n_facets(); ++f) {
    const auto facet = pair.slave.facet(f);
    bool touches = false;
    for (int node : facet) touches = touches || around[node] != 0;
    if (touches)
      for (int node : facet) slave_moves[node] = 1;
  }
  // Central differences of the terms over each free coordinate that moves.
  const double step = 1e-7 * reference_sizes_[p];
  std::vector<double> slave_x = pair.slave_x, master_x = pair.master_x;
  std::vector<double> plus_s, plus_m, minus_s, minus_m;
  const auto emit = [&](PetscInt column) {
    const auto add = [&](const Surface& surface, const std::vector<double>& plus,
                         const std::vector<double>& minus) {
      for (int node = 0; node < surface.n_nodes(); ++node)
        for (int a = 0; a < dim_; ++a) {
          const std::size_t k = static_cast<std::size_t>(node) * dim_ + a;
          const double derivative = (plus[k] - minus[k]) / (2.0 * step);
          if (derivative == 0.0) continue;
          const PetscInt row = surface.global_vertex[node] * dim_ + a;
          if (row < first_dof_ || row >= end_dof_ || prescribed(row)) continue;
          rows.push_back(row);
          columns.push_back(column);
          values.push_back(derivative);
        }
    };
    add(pair.slave, plus_s, minus_s);
    add(pair.master, plus_m, minus_m);
  };
  const auto differentiate = [&](std::vector<double>& x, std::size_t k, PetscInt column) {
    const double x0 = x[k];
    x[k] = x0 + step;
    contact_terms(p, slave_x, master_x, plus_s, plus_m);
    x[k] = x0 - step;
    contact_terms(p, slave_x, master_x, minus_s, minus_m);
    x[k] = x0;
    emit(column);
  };
  for (int node = 0; node < pair.slave.n_nodes(); ++node)
    for (int b = 0; b < dim_ && slave_moves[node]; ++b) {
      const std::size_t k = static_cast<std::size_t>(node) * dim_ + b;
      if (!pair.dirichlet[k]) differentiate(slave_x, k, pair.slave.global_vertex[node] * dim_ + b);
    }
  for (int node = 0; node < pair.master.n_nodes(); ++node)
    for (int b = 0; b < dim_ && master_moves[node]; ++b) {
      const std::size_t k = static_cast<std::size_t>(node) * dim_ + b;
      if (!pair.master_dirichlet[k])
        differentiate(master_x, k, pair.master.global_vertex[node] * dim_ + b);
    }
}

void ContactConstraints::vertex_fields(std::vector<double>& pressure, std::vector<double>& gap,
                                       std::vector<double>& active) const {
  const std::size_t n = static_cast<std::size_t>(mesh_.n_vertices());
  pressure.assign(n, 0.0);
  gap.assign(n, 0.0);
  active.assign(n, 0.0);
  std::unordered_map<PetscInt, int> local;
  for (int v = 0; v < mesh_.n_vertices(); ++v) local.emplace(mesh_.global_vertex[v], v);
  for (const auto& pair : pairs_)
    for (int j = 0; j < pair.slave.n_nodes(); ++j) {
      const auto found = local.find(pair.slave.global_vertex[j]);
      if (found == local.end()) continue;
      pressure[found->second] = pair.pressure[j];
      gap[found->second] = pair.mortar.multiplier.empty() ? 0.0 : pair.mortar.gap(j);
      active[found->second] = pair.active[j] ? 1.0 : 0.0;
    }
}

std::string ContactConstraints::describe() const {
  std::string text;
  for (std::size_t p = 0; p < pairs_.size(); ++p)
    text += fmt::format("{}slave '{}' ({} facets) / master '{}' ({} facets)", p ? "; " : "",
                        pairs_[p].slave.name, pairs_[p].slave.n_facets(), pairs_[p].master.name,
                        pairs_[p].master.n_facets());
  return text;
}

}  // namespace coapt::contact
