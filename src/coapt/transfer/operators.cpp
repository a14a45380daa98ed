/// @file operators.cpp
/// Stage 3 of the transfer pipeline: integration over the pairs and PETSc assembly.
///
/// Search, integration and local sums in one sweep over the owned slave cells (Engine::
/// integrate, PairSearch::sweep): the advancing front hands each candidate pair to the
/// intersection kernel, and the integrals of a cell's overlapping pairs are added into
/// per-row lists over (local slave vertex, received master vertex) that grow as columns
/// appear, found through a scratch table indexed by master vertex (one indexed add per entry,
/// no search). Rows are sorted by column at the end, so the pattern depends only on which
/// pairs overlap; only entries an overlapping pair reaches exist, so B holds no structural
/// zeros. Nothing is allocated per pair; the row lists grow by doubling.

#include "coapt/transfer/operators.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <span>
#include <string>

#include "coapt/core/error.hpp"
#include "coapt/transfer/intersection.hpp"

namespace coapt::transfer {

namespace detail {

/// What one integration produces on a rank (dimension-free).
struct LocalOperators {
  std::vector<int> row_offsets;       ///< per local slave vertex + 1
  std::vector<int> columns;           ///< received master vertex (ascending within a row)
  std::vector<double> dual;           ///< ∫_Ω ψ_i φ_j
  std::vector<double> primal;         ///< ∫_Ω λ_i φ_j (primal or standard only)
  std::vector<double> dual_integral;  ///< per local slave vertex: ∫_Ω ψ_i (owned cells' part)
  std::vector<double> covered;        ///< ∫_Ω λ_i
  std::vector<double> full;           ///< ∫_S λ_i
  std::vector<double> cell_coverage;  ///< per owned slave cell T: |T ∩ M| / |T|
  std::vector<int> mass_cells;        ///< owned slave cells with overlap (standard only)
  std::vector<double> mass_blocks;    ///< (d+1)² values of ∫_Ω λ_a λ_b per mass cell
  std::int64_t intersecting_pairs = 0;
  double intersection_seconds = 0;
};

class TransferEngine {
 public:
  virtual ~TransferEngine() = default;
  virtual bool update_master(const mesh::Mesh& master) = 0;
  /// `primal`: also ∫_Ω λ_i φ_j; `overlap_mass`: also the blocks ∫_Ω λ_a λ_b.
  virtual void integrate(bool primal, bool overlap_mass, LocalOperators& out) = 0;
  virtual const SearchStatistics& search_statistics() const = 0;
  virtual std::span<const PetscInt> master_vertex_global() const = 0;
};

template <int dim>
class Engine final : public TransferEngine {
 public:
  Engine(const mesh::Mesh& slave, const mesh::Mesh& master, const SearchOptions& options)
      : search_(slave, master, options) {}

  bool update_master(const mesh::Mesh& master) override { return search_.update_master(master); }
  const SearchStatistics& search_statistics() const override { return search_.statistics(); }
  std::span<const PetscInt> master_vertex_global() const override {
    return search_.master().vertex_global;
  }

  // The search and the integration in one sweep (PairSearch::sweep): the advancing front
  // tests each candidate pair with the intersection kernel itself, whose rejection tests are
  // the front's (a separated pair is not crossed) and whose integrals of an overlapping pair
  // are kept until the slave cell is done. Then the cell's pairs are added into the rows of
  // its vertices: row r is a list of (received master vertex, value) that grows as new
  // columns appear (found through slots_, a table indexed by master vertex that holds, for
  // the current cell, the position of that column in each of the cell's rows); at the end
  // each row is sorted by column, so the pattern does not depend on the order the pairs
  // were found in. Only entries an overlapping pair reaches are ever created.
  void integrate(bool primal, bool overlap_mass, LocalOperators& out) override {
    constexpr int k = dim + 1;
    const mesh::Mesh& slave = search_.slave();
    const ReceivedMaster<dim>& received = search_.master();
    const std::span<const Simplex<dim>> master_simplices = search_.master_simplices();
    const int n_rows = slave.n_vertices();
    const int n_columns = received.n_vertices();

    rows_.assign(static_cast<std::size_t>(n_rows), Row{});
    slot_stamp_.assign(static_cast<std::size_t>(n_columns), -1);
    slots_.resize(static_cast<std::size_t>(n_columns) * k);
    out.dual_integral.assign(static_cast<std::size_t>(n_rows), 0.0);
    out.covered.assign(static_cast<std::size_t>(n_rows), 0.0);
    out.full.assign(static_cast<std::size_t>(n_rows), 0.0);
    out.cell_coverage.assign(static_cast<std::size_t>(slave.n_owned_cells), 0.0);
    out.mass_cells.clear();
    out.mass_blocks.clear();
    workspace_.second_moment = overlap_mass;  // mass_matrix() needs it, B and D do not
    std::size_t n_hits = 0;  // integrals of the current cell's overlapping pairs in buffer_

    const auto test = [&](int, const Simplex<dim>& s, int m, unsigned& crossed) {
      if (n_hits == buffer_.size()) buffer_.resize(2 * n_hits + 32);
      const Contact contact =
          local_integrals_contact(s, master_simplices[m], workspace_, buffer_[n_hits]);
      crossed = buffer_[n_hits].crossed_faces_b;
      if (contact == Contact::overlapping) ++n_hits;
      return contact;
    };
    const auto finish = [&](int c, const Simplex<dim>& s, std::span<const int> pairs) {
      COAPT_ASSERT(pairs.size() == n_hits, "one integral per overlapping pair");
      const int* vertices = slave.cells.data() + static_cast<std::size_t>(c) * k;
      for (int a = 0; a < k; ++a) out.full[vertices[a]] += s.measure / k;
      if (n_hits == 0) return;
      std::array<Row*, k> row;
      for (int a = 0; a < k; ++a) row[a] = &rows_[static_cast<std::size_t>(vertices[a])];
      // slots of the columns the cell's rows already have
      const auto stamp = [&](int column) {
        int* slot = slots_.data() + static_cast<std::size_t>(column) * k;
        if (slot_stamp_[column] != c) {
          slot_stamp_[column] = c;
          for (int a = 0; a < k; ++a) slot[a] = -1;
        }
        return slot;
      };
      for (int a = 0; a < k; ++a)
        for (std::size_t e = 0; e < row[a]->columns.size(); ++e)
          stamp(row[a]->columns[e])[a] = static_cast<int>(e);
      // Pass 1: an entry for every (row, column) the cell's pairs reach (rows only grow here).
      for (std::size_t q = 0; q < n_hits; ++q) {
        const int* columns = received.cells.data() + static_cast<std::size_t>(pairs[q]) * k;
        for (int b = 0; b < k; ++b) {
          int* slot = stamp(columns[b]);
          for (int a = 0; a < k; ++a) {
            if (slot[a] >= 0) continue;
            Row& r = *row[a];
            slot[a] = static_cast<int>(r.columns.size());
            r.columns.push_back(columns[b]);
            r.dual.push_back(0.0);
            if (primal) r.primal.push_back(0.0);
          }
        }
      }
      // Pass 2: the sums, through stable pointers (no branch, no reload per add).
      std::array<double*, k> dual_row, primal_row{};
      for (int a = 0; a < k; ++a) {
        dual_row[a] = row[a]->dual.data();
        if (primal) primal_row[a] = row[a]->primal.data();
      }
      NodalMatrix<dim> mass_block{};
      double overlap = 0;  // |T ∩ M| = Σ_a ∫_Ω λ_a (the λ_a sum to 1)
      for (std::size_t q = 0; q < n_hits; ++q) {
        const LocalIntegrals<dim>& local = buffer_[q];
        const NodalMatrix<dim> dual = dual_mass(local);
        const NodalVector<dim> dual_integral = dual_integrals(local);
        const int* columns = received.cells.data() + static_cast<std::size_t>(pairs[q]) * k;
        for (int b = 0; b < k; ++b) {
          const int* slot = slots_.data() + static_cast<std::size_t>(columns[b]) * k;
          for (int a = 0; a < k; ++a) dual_row[a][slot[a]] += dual[a][b];
          if (primal)
            for (int a = 0; a < k; ++a) primal_row[a][slot[a]] += local.mass[a][b];
        }
        for (int a = 0; a < k; ++a) {
          out.dual_integral[vertices[a]] += dual_integral[a];
          out.covered[vertices[a]] += local.integral_a[a];
          overlap += local.integral_a[a];
        }
        if (overlap_mass) {
          const NodalMatrix<dim> m = mass_matrix(local.moments, s, s);
          for (int a = 0; a < k; ++a)
            for (int b = 0; b < k; ++b) mass_block[a][b] += m[a][b];
        }
      }
      out.cell_coverage[static_cast<std::size_t>(c)] = overlap / s.measure;
      if (overlap_mass) {
        out.mass_cells.push_back(c);
        for (int a = 0; a < k; ++a)
          for (int b = 0; b < k; ++b) out.mass_blocks.push_back(mass_block[a][b]);
      }
      n_hits = 0;
    };
    search_.sweep(test, finish);
    search_.release_pairs();  // memory: the pair list was only needed for the seeds
    out.intersecting_pairs = search_.statistics().pairs;
    out.intersection_seconds = search_.statistics().query_seconds;

    // Rows sorted by column into the CSR (the row lists are freed as they are copied).
    out.row_offsets.assign(static_cast<std::size_t>(n_rows) + 1, 0);
    std::size_t n_entries = 0;
    for (int r = 0; r < n_rows; ++r) {
      n_entries += rows_[static_cast<std::size_t>(r)].columns.size();
      out.row_offsets[r + 1] = static_cast<int>(n_entries);
    }
    out.columns.resize(n_entries);
    out.dual.resize(n_entries);
    out.primal.resize(primal ? n_entries : 0);
    std::vector<int> order;
    for (int r = 0; r < n_rows; ++r) {
      Row& row = rows_[static_cast<std::size_t>(r)];
      order.resize(row.columns.size());
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(),
                [&](int x, int y) { return row.columns[x] < row.columns[y]; });
      const std::size_t first = static_cast<std::size_t>(out.row_offsets[r]);
      for (std::size_t e = 0; e < order.size(); ++e) {
        out.columns[first + e] = row.columns[order[e]];
        out.dual[first + e] = row.dual[order[e]];
        if (primal) out.primal[first + e] = row.primal[order[e]];
      }
      row = Row{};
    }
    rows_ = std::vector<Row>();
  }

 private:
  PairSearch<dim> search_;
  // scratch, kept between integrations
  struct Row {  ///< one slave vertex's entries while they are summed, in order of creation
    std::vector<int> columns;  ///< received master vertex
    std::vector<double> dual, primal;
  };
  std::vector<Row> rows_;
  std::vector<int> slot_stamp_;  ///< per received master vertex: the cell its slots are for
  std::vector<int> slots_;       ///< per received master vertex, its entry in each row of the cell
  std::vector<LocalIntegrals<dim>> buffer_;
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
  SearchOptions search;
  search.margin = options.search_margin;
  search.front = true;
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
  if (rows) {        // new pattern: create the matrix (PETSc may reorder the index arrays)
    matrix.reset();  // memory: the old matrix is not needed while the new one is set up
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
  const bool primal = options_.standard || options_.primal;
  engine_->integrate(primal, options_.standard, local);
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
                     (!primal || standard_coupling_)
                 ? 1
                 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_MIN, slave.comm);
  const bool reuse = same == 1;
  pattern_hash_ = hash;
  pattern_size_ = rows.size();
  if (reuse) {
    assemble_matrix(coupling_, nullptr, nullptr, local.dual);
    if (primal) assemble_matrix(standard_coupling_, nullptr, nullptr, local.primal);
  } else {
    if (primal) {
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
  covered_integral_ = sum_vertex_values(slave, local.covered);
  cell_coverage_ = std::move(local.cell_coverage);
  const Vec covered = covered_integral_.get();
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
