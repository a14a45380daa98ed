/// @file operators.cpp
/// Stage 3 of the transfer pipeline: integration over the pairs and PETSc assembly.
///
/// Local sums. The rank's contributions are summed in a CSR over (local slave vertex,
/// received master vertex) before PETSc sees them. The pattern comes from the pair list
/// (row r: the vertices of every master cell paired with an owned slave cell around r); the
/// integration then runs slave cell by slave cell: the positions of the cell's rows are
/// written into a scratch table indexed by master vertex, so each of the (d+1)² entries of a
/// pair is one indexed add. Entries no intersecting pair touched (pairs the separating-plane
/// filter kept but whose intersection is empty) are dropped before assembly, so B holds no
/// structural zeros. Nothing is allocated per pair or per cell (the scratch only grows).

#include "coapt/transfer/operators.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>
#include <string>

#include "coapt/core/error.hpp"
#include "coapt/transfer/intersection.hpp"

namespace coapt::transfer {

namespace detail {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
}  // namespace

/// What one integration produces on a rank (dimension-free).
struct LocalOperators {
  std::vector<int> row_offsets;       ///< per local slave vertex + 1
  std::vector<int> columns;           ///< received master vertex (ascending within a row)
  std::vector<double> dual;           ///< ∫_Ω ψ_i φ_j
  std::vector<double> primal;         ///< ∫_Ω λ_i φ_j (standard only)
  std::vector<double> dual_integral;  ///< per local slave vertex: ∫_Ω ψ_i (owned cells' part)
  std::vector<double> covered;        ///< ∫_Ω λ_i
  std::vector<double> full;           ///< ∫_S λ_i
  std::vector<int> mass_cells;        ///< owned slave cells with overlap (standard only)
  std::vector<double> mass_blocks;    ///< (d+1)² values of ∫_Ω λ_a λ_b per mass cell
  std::int64_t intersecting_pairs = 0;
  double intersection_seconds = 0;
};

class TransferEngine {
 public:
  virtual ~TransferEngine() = default;
  virtual bool update_master(const mesh::Mesh& master) = 0;
  virtual void integrate(bool standard, LocalOperators& out) = 0;
  virtual const SearchStatistics& search_statistics() const = 0;
  virtual std::span<const PetscInt> master_vertex_global() const = 0;
};

template <int dim>
class Engine final : public TransferEngine {
 public:
  Engine(const mesh::Mesh& slave, const mesh::Mesh& master, const SearchOptions& options)
      : search_(slave, master, options) {
    // owned cells around each local slave vertex (the slave does not move)
    const int n = slave.n_vertices();
    vertex_cell_offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
    for (int c = 0; c < slave.n_owned_cells; ++c)
      for (int v : slave.cell(c)) ++vertex_cell_offsets_[v + 1];
    for (int v = 0; v < n; ++v) vertex_cell_offsets_[v + 1] += vertex_cell_offsets_[v];
    vertex_cells_.resize(static_cast<std::size_t>(vertex_cell_offsets_.back()));
    std::vector<int> fill(vertex_cell_offsets_.begin(), vertex_cell_offsets_.end() - 1);
    for (int c = 0; c < slave.n_owned_cells; ++c)
      for (int v : slave.cell(c)) vertex_cells_[fill[v]++] = c;
  }

  bool update_master(const mesh::Mesh& master) override { return search_.update_master(master); }
  const SearchStatistics& search_statistics() const override { return search_.statistics(); }
  std::span<const PetscInt> master_vertex_global() const override {
    return search_.master().vertex_global;
  }

  void integrate(bool standard, LocalOperators& out) override {
    constexpr int k = dim + 1;
    const mesh::Mesh& slave = search_.slave();
    const ReceivedMaster<dim>& received = search_.master();
    const std::span<const Simplex<dim>> master_simplices = search_.master_simplices();
    const int n_rows = slave.n_vertices();
    const int n_columns = received.n_vertices();

    // Pattern: row r gets the vertices of the master cells paired with its owned cells.
    out.row_offsets.assign(static_cast<std::size_t>(n_rows) + 1, 0);
    out.columns.clear();
    stamp_.assign(static_cast<std::size_t>(n_columns), -1);
    for (int r = 0; r < n_rows; ++r) {
      const std::size_t first = out.columns.size();
      for (int a = vertex_cell_offsets_[r]; a < vertex_cell_offsets_[r + 1]; ++a) {
        for (const int m : search_.pairs_of(vertex_cells_[a])) {
          const int* vertices = received.cells.data() + static_cast<std::size_t>(m) * k;
          for (int b = 0; b < k; ++b)
            if (stamp_[vertices[b]] != r) {
              stamp_[vertices[b]] = r;
              out.columns.push_back(vertices[b]);
            }
        }
      }
      std::sort(out.columns.begin() + static_cast<std::ptrdiff_t>(first), out.columns.end());
      out.row_offsets[r + 1] = static_cast<int>(out.columns.size());
    }
    const std::size_t n_entries = out.columns.size();
    out.dual.assign(n_entries, 0.0);
    if (standard)
      out.primal.assign(n_entries, 0.0);
    else
      out.primal.clear();
    touched_.assign(n_entries, 0);
    out.dual_integral.assign(static_cast<std::size_t>(n_rows), 0.0);
    out.covered.assign(static_cast<std::size_t>(n_rows), 0.0);
    out.full.assign(static_cast<std::size_t>(n_rows), 0.0);
    out.mass_cells.clear();
    out.mass_blocks.clear();
    slots_.resize(static_cast<std::size_t>(n_columns) * k);
    out.intersecting_pairs = 0;
    double intersection_seconds = 0;

    for (int c = 0; c < slave.n_owned_cells; ++c) {
      const Simplex<dim> s = cell_simplex<dim>(slave, c);
      const int* rows = slave.cells.data() + static_cast<std::size_t>(c) * k;
      for (int a = 0; a < k; ++a) out.full[rows[a]] += s.measure / k;
      const std::span<const int> pairs = search_.pairs_of(c);
      const std::size_t n_pairs = pairs.size();
      if (n_pairs == 0) continue;
      if (buffer_.size() < n_pairs) {
        buffer_.resize(n_pairs);
        hit_.resize(n_pairs);
      }
      // intersections
      const Clock::time_point start = Clock::now();
      for (std::size_t q = 0; q < n_pairs; ++q)
        hit_[q] = local_integrals(s, master_simplices[pairs[q]], workspace_, buffer_[q]);
      const Clock::time_point integrated = Clock::now();
      intersection_seconds += seconds_between(start, integrated);
      // sums
      for (int a = 0; a < k; ++a)
        for (int e = out.row_offsets[rows[a]]; e < out.row_offsets[rows[a] + 1]; ++e)
          slots_[static_cast<std::size_t>(out.columns[e]) * k + a] = e;
      NodalMatrix<dim> mass_block{};
      bool any = false;
      for (std::size_t q = 0; q < n_pairs; ++q) {
        if (!hit_[q]) continue;
        any = true;
        ++out.intersecting_pairs;
        const LocalIntegrals<dim>& local = buffer_[q];
        const NodalMatrix<dim> dual = dual_mass(local);
        const NodalVector<dim> dual_integral = dual_integrals(local);
        const int* columns = received.cells.data() + static_cast<std::size_t>(pairs[q]) * k;
        for (int b = 0; b < k; ++b) {
          const int* slot = slots_.data() + static_cast<std::size_t>(columns[b]) * k;
          for (int a = 0; a < k; ++a) {
            out.dual[slot[a]] += dual[a][b];
            touched_[slot[a]] = 1;
          }
          if (standard)
            for (int a = 0; a < k; ++a) out.primal[slot[a]] += local.mass[a][b];
        }
        for (int a = 0; a < k; ++a) {
          out.dual_integral[rows[a]] += dual_integral[a];
          out.covered[rows[a]] += local.integral_a[a];
        }
        if (standard) {
          const NodalMatrix<dim> m = mass_matrix(local.moments, s, s);
          for (int a = 0; a < k; ++a)
            for (int b = 0; b < k; ++b) mass_block[a][b] += m[a][b];
        }
      }
      if (standard && any) {
        out.mass_cells.push_back(c);
        for (int a = 0; a < k; ++a)
          for (int b = 0; b < k; ++b) out.mass_blocks.push_back(mass_block[a][b]);
      }
    }
    out.intersection_seconds = intersection_seconds;

    // Drop the entries no intersecting pair reached.
    std::size_t write = 0, read = 0;
    for (int r = 0; r < n_rows; ++r) {
      const std::size_t end = static_cast<std::size_t>(out.row_offsets[r + 1]);
      out.row_offsets[r] = static_cast<int>(write);
      for (; read < end; ++read)
        if (touched_[read]) {
          out.columns[write] = out.columns[read];
          out.dual[write] = out.dual[read];
          if (standard) out.primal[write] = out.primal[read];
          ++write;
        }
    }
    out.row_offsets[n_rows] = static_cast<int>(write);
    out.columns.resize(write);
    out.dual.resize(write);
    out.columns.shrink_to_fit();
    out.dual.shrink_to_fit();
    if (standard) {
      out.primal.resize(write);
      out.primal.shrink_to_fit();
    }
  }

 private:
  PairSearch<dim> search_;
  std::vector<int> vertex_cell_offsets_, vertex_cells_;
  // scratch, kept between integrations
  std::vector<int> stamp_;
  std::vector<int> slots_;  ///< per received master vertex, the entry of each row of the cell
  std::vector<unsigned char> touched_;
  std::vector<LocalIntegrals<dim>> buffer_;
  std::vector<unsigned char> hit_;
  IntersectionWorkspace<dim> workspace_;
};

}  // namespace detail

namespace {

using detail::LocalOperators;
using Clock = std::chrono::steady_clock;

OwnedVec layout_vector(MPI_Comm comm, const mesh::Mesh& mesh) {
  OwnedVec v;
  COAPT_PETSC_CHECK(VecCreateMPI(comm, mesh.n_owned_vertices, mesh.n_global_vertices, v.out()));
  return v;
}

/// Sums per-local-vertex values into a vector of the mesh's layout (ghost rows travel).
OwnedVec sum_vertex_values(const mesh::Mesh& mesh, const std::vector<double>& values) {
  OwnedVec v = layout_vector(mesh.comm, mesh);
  std::vector<PetscInt> rows;
  std::vector<PetscScalar> entries;
  rows.reserve(values.size());
  entries.reserve(values.size());
  for (std::size_t r = 0; r < values.size(); ++r)
    if (values[r] != 0.0 || static_cast<int>(r) < mesh.n_owned_vertices) {
      rows.push_back(mesh.global_vertex[r]);
      entries.push_back(values[r]);
    }
  COAPT_PETSC_CHECK(
      VecSetValues(v, static_cast<PetscInt>(rows.size()), rows.data(), entries.data(), ADD_VALUES));
  COAPT_PETSC_CHECK(VecAssemblyBegin(v));
  COAPT_PETSC_CHECK(VecAssemblyEnd(v));
  return v;
}

}  // namespace

VariationalTransfer::VariationalTransfer(const mesh::Mesh& slave, const mesh::Mesh& master,
                                         const TransferOptions& options)
    : slave_(&slave), master_(&master), options_(options) {
  if (slave.dim != master.dim)
    throw InputError("transfer: slave mesh '" + slave.source + "' has dimension " +
                     std::to_string(slave.dim) + ", master mesh '" + master.source + "' has " +
                     std::to_string(master.dim));
  if (!(options.coverage_threshold > 0.0 && options.coverage_threshold <= 1.0))
    throw InputError("transfer: coverage_threshold must lie in (0, 1]");
  const auto start = Clock::now();
  const SearchOptions search{options.search_margin};
  if (slave.dim == 2)
    engine_ = std::make_unique<detail::Engine<2>>(slave, master, search);
  else if (slave.dim == 3)
    engine_ = std::make_unique<detail::Engine<3>>(slave, master, search);
  else
    throw InputError("transfer: meshes of dimension 2 or 3 expected, got " +
                     std::to_string(slave.dim));
  statistics_.search_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  assemble();
}

VariationalTransfer::~VariationalTransfer() = default;

void VariationalTransfer::update_master(const mesh::Mesh& master) {
  master_ = &master;
  const auto start = Clock::now();
  engine_->update_master(master);
  statistics_.search_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  assemble();
}

void VariationalTransfer::assemble_matrix(OwnedMat& matrix, std::vector<PetscInt>* rows,
                                          std::vector<PetscInt>* columns,
                                          const std::vector<double>& values) {
  if (rows) {  // new pattern: create the matrix (PETSc may reorder the index arrays)
    OwnedMat created;
    COAPT_PETSC_CHECK(MatCreate(slave_->comm, created.out()));
    COAPT_PETSC_CHECK(MatSetSizes(created, slave_->n_owned_vertices, master_->n_owned_vertices,
                                  slave_->n_global_vertices, master_->n_global_vertices));
    COAPT_PETSC_CHECK(MatSetType(created, MATAIJ));
    COAPT_PETSC_CHECK(MatSetPreallocationCOO(created, static_cast<PetscCount>(rows->size()),
                                             rows->data(), columns->data()));
    matrix = std::move(created);
  }
  COAPT_PETSC_CHECK(MatSetValuesCOO(matrix, values.data(), INSERT_VALUES));
}

void VariationalTransfer::assemble() {
  const auto start = Clock::now();
  const mesh::Mesh& slave = *slave_;
  LocalOperators local;
  engine_->integrate(options_.standard, local);
  statistics_.search = engine_->search_statistics();
  statistics_.intersecting_pairs = local.intersecting_pairs;
  statistics_.intersection_seconds = local.intersection_seconds;
  statistics_.local_entries = static_cast<std::int64_t>(local.columns.size());

  // B (and B^std) through COO, re-using the matrix when the pattern is unchanged.
  const std::span<const PetscInt> master_global = engine_->master_vertex_global();
  std::vector<PetscInt> rows(local.columns.size()), columns(local.columns.size());
  for (int r = 0; r < slave.n_vertices(); ++r)
    for (int e = local.row_offsets[r]; e < local.row_offsets[r + 1]; ++e) {
      rows[e] = slave.global_vertex[r];
      columns[e] = master_global[local.columns[e]];
    }
  local.columns = std::vector<int>();  // memory: PETSc's COO set-up is the peak
  local.row_offsets = std::vector<int>();
  // The pattern is compared through a 64-bit hash (FNV-1a) rather than kept; the decision is
  // collective, every rank must take the same path through PETSc.
  std::uint64_t hash = 14695981039346656037ULL;
  auto mix = [&hash](std::uint64_t value) {
    for (int byte = 0; byte < 8; ++byte, value >>= 8) {
      hash ^= value & 0xff;
      hash *= 1099511628211ULL;
    }
  };
  for (std::size_t e = 0; e < rows.size(); ++e) {
    mix(static_cast<std::uint64_t>(rows[e]));
    mix(static_cast<std::uint64_t>(columns[e]));
  }
  int same = coupling_ && hash == pattern_hash_ && rows.size() == pattern_size_ &&
                     (!options_.standard || standard_coupling_)
                 ? 1
                 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, slave.comm);
  const bool reuse = same == 1;
  pattern_hash_ = hash;
  pattern_size_ = rows.size();
  if (reuse) {
    assemble_matrix(coupling_, nullptr, nullptr, local.dual);
    if (options_.standard) assemble_matrix(standard_coupling_, nullptr, nullptr, local.primal);
  } else {
    if (options_.standard) {
      std::vector<PetscInt> i = rows, j = columns;
      assemble_matrix(standard_coupling_, &i, &j, local.primal);
    }
    assemble_matrix(coupling_, &rows, &columns, local.dual);
  }
  rows = std::vector<PetscInt>();
  columns = std::vector<PetscInt>();
  statistics_.pattern_reused = reuse;

  // D, the coverage and the constrained set.
  dual_mass_ = sum_vertex_values(slave, local.dual_integral);
  OwnedVec covered = sum_vertex_values(slave, local.covered);
  OwnedVec full = sum_vertex_values(slave, local.full);
  if (!coverage_) coverage_ = layout_vector(slave.comm, slave);
  if (!work_slave_) work_slave_ = layout_vector(slave.comm, slave);
  constrained_rows_.clear();
  constrained_local_.clear();
  inverse_dual_.clear();
  std::vector<PetscInt> uncovered;  // owned rows without any overlap (standard variant)
  {
    const PetscScalar *d = nullptr, *cov = nullptr, *all = nullptr;
    PetscScalar* fraction = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(dual_mass_, &d));
    COAPT_PETSC_CHECK(VecGetArrayRead(covered, &cov));
    COAPT_PETSC_CHECK(VecGetArrayRead(full, &all));
    COAPT_PETSC_CHECK(VecGetArray(coverage_, &fraction));
    for (int r = 0; r < slave.n_owned_vertices; ++r) {
      fraction[r] = all[r] > 0.0 ? cov[r] / all[r] : 0.0;
      if (fraction[r] >= options_.coverage_threshold && d[r] > 0.0) {
        constrained_rows_.push_back(slave.global_vertex[r]);
        constrained_local_.push_back(r);
        inverse_dual_.push_back(1.0 / d[r]);
      }
      if (!(cov[r] > 0.0)) uncovered.push_back(slave.global_vertex[r]);
    }
    COAPT_PETSC_CHECK(VecRestoreArray(coverage_, &fraction));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(full, &all));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(covered, &cov));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(dual_mass_, &d));
  }
  COAPT_PETSC_CHECK(ISCreateGeneral(slave.comm, static_cast<PetscInt>(constrained_rows_.size()),
                                    constrained_rows_.data(), PETSC_COPY_VALUES,
                                    constrained_set_.out()));
  PetscInt n = static_cast<PetscInt>(constrained_rows_.size());
  MPI_Allreduce(&n, &n_constrained_, 1, MPIU_INT, MPI_SUM, slave.comm);

  // Standard variant: M_S from the per-cell blocks, identity on rows without overlap.
  if (options_.standard) {
    constexpr int max_k = 4;
    const int k = slave.dim + 1;
    std::vector<PetscInt> i, j;
    std::vector<PetscScalar> values;
    const std::size_t n_entries = local.mass_cells.size() * k * k + uncovered.size();
    i.reserve(n_entries);
    j.reserve(n_entries);
    values.reserve(n_entries);
    for (std::size_t m = 0; m < local.mass_cells.size(); ++m) {
      const auto vertices = slave.cell(local.mass_cells[m]);
      PetscInt global[max_k];
      for (int a = 0; a < k; ++a) global[a] = slave.global_vertex[vertices[a]];
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
          i.push_back(global[a]);
          j.push_back(global[b]);
          values.push_back(local.mass_blocks[m * k * k + a * k + b]);
        }
    }
    for (PetscInt row : uncovered) {
      i.push_back(row);
      j.push_back(row);
      values.push_back(1.0);
    }
    OwnedMat mass;
    COAPT_PETSC_CHECK(MatCreate(slave.comm, mass.out()));
    COAPT_PETSC_CHECK(MatSetSizes(mass, slave.n_owned_vertices, slave.n_owned_vertices,
                                  slave.n_global_vertices, slave.n_global_vertices));
    COAPT_PETSC_CHECK(MatSetType(mass, MATAIJ));
    COAPT_PETSC_CHECK(
        MatSetPreallocationCOO(mass, static_cast<PetscCount>(i.size()), i.data(), j.data()));
    COAPT_PETSC_CHECK(MatSetValuesCOO(mass, values.data(), INSERT_VALUES));
    COAPT_PETSC_CHECK(MatSetOption(mass, MAT_SYMMETRIC, PETSC_TRUE));
    overlap_mass_ = std::move(mass);
    if (!standard_solver_) {
      COAPT_PETSC_CHECK(KSPCreate(slave.comm, standard_solver_.out()));
      COAPT_PETSC_CHECK(KSPSetOptionsPrefix(standard_solver_, "transfer_standard_"));
      COAPT_PETSC_CHECK(KSPSetType(standard_solver_, KSPCG));
      PC pc = nullptr;
      COAPT_PETSC_CHECK(KSPGetPC(standard_solver_, &pc));
      COAPT_PETSC_CHECK(PCSetType(pc, PCJACOBI));
      COAPT_PETSC_CHECK(KSPSetTolerances(standard_solver_, 1e-14, 1e-300, PETSC_DEFAULT, 10000));
      COAPT_PETSC_CHECK(KSPSetFromOptions(standard_solver_));
    }
    COAPT_PETSC_CHECK(KSPSetOperators(standard_solver_, overlap_mass_, overlap_mass_));
  }
  const double total = std::chrono::duration<double>(Clock::now() - start).count();
  statistics_.assembly_seconds = total - statistics_.intersection_seconds;
}

void VariationalTransfer::apply_transfer(Vec master_values, Vec slave_values) const {
  COAPT_PETSC_CHECK(MatMult(coupling_, master_values, work_slave_));
  const PetscScalar* product = nullptr;
  PetscScalar* out = nullptr;
  COAPT_PETSC_CHECK(VecGetArrayRead(work_slave_, &product));
  COAPT_PETSC_CHECK(VecGetArray(slave_values, &out));
  for (std::size_t q = 0; q < constrained_local_.size(); ++q)
    out[constrained_local_[q]] = product[constrained_local_[q]] * inverse_dual_[q];
  COAPT_PETSC_CHECK(VecRestoreArray(slave_values, &out));
  COAPT_PETSC_CHECK(VecRestoreArrayRead(work_slave_, &product));
}

OwnedMat VariationalTransfer::explicit_transfer() const {
  OwnedMat transfer;
  COAPT_PETSC_CHECK(MatDuplicate(coupling_, MAT_COPY_VALUES, transfer.out()));
  OwnedVec scale = layout_vector(slave_->comm, *slave_);
  COAPT_PETSC_CHECK(VecSet(scale, 0.0));
  PetscScalar* s = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(scale, &s));
  for (std::size_t q = 0; q < constrained_local_.size(); ++q)
    s[constrained_local_[q]] = inverse_dual_[q];
  COAPT_PETSC_CHECK(VecRestoreArray(scale, &s));
  COAPT_PETSC_CHECK(MatDiagonalScale(transfer, scale, nullptr));
  return transfer;
}

void VariationalTransfer::apply_standard_transfer(Vec master_values, Vec slave_values) const {
  if (!options_.standard)
    throw InputError(
        "transfer: the standard variant was not assembled (TransferOptions::standard)");
  OwnedVec rhs = layout_vector(slave_->comm, *slave_);
  COAPT_PETSC_CHECK(MatMult(standard_coupling_, master_values, rhs));
  COAPT_PETSC_CHECK(VecSet(slave_values, 0.0));
  COAPT_PETSC_CHECK(KSPSolve(standard_solver_, rhs, slave_values));
  KSPConvergedReason reason;
  COAPT_PETSC_CHECK(KSPGetConvergedReason(standard_solver_, &reason));
  if (reason < 0) {
    PetscInt iterations = 0;
    KSPGetIterationNumber(standard_solver_, &iterations);
    throw ConvergenceError("transfer: CG on the overlap mass matrix failed (" +
                           std::string(KSPConvergedReasons[reason]) + " after " +
                           std::to_string(iterations) + " iterations)");
  }
}

OwnedVec VariationalTransfer::create_slave_vector() const {
  return layout_vector(slave_->comm, *slave_);
}

OwnedVec VariationalTransfer::create_master_vector() const {
  return layout_vector(master_->comm, *master_);
}

}  // namespace coapt::transfer
