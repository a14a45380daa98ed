// The transfer operators on 1, 2 and 3 ranks with independently partitioned meshes (slave by
// METIS, master in blocks: the partitions do not align) against the same operators built on
// one rank from the whole meshes. The global numbering depends on the partition, so B and D
// are compared entry by entry through the generators' original vertex numbers, next to the
// partition-independent figures: Σ B, ‖B‖_F, the number of constrained nodes, and T applied
// to a linear field at every constrained node against the exact values.

#include <gtest/gtest.h>
#include <petscmat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <tuple>

#include "../support/mesh_transforms.hpp"
#include "coapt/core/context.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/transfer/operators.hpp"

namespace {

using coapt::OwnedMat;
using coapt::OwnedVec;
using coapt::mesh::Mesh;
using coapt::mesh::Partitioner;
using coapt::transfer::TransferOptions;
using coapt::transfer::VariationalTransfer;

const MPI_Comm kWorld = MPI_COMM_WORLD;

/// A configuration: whole slave and master meshes (built on every rank, cheap).
struct Configuration {
  std::string name;
  std::function<Mesh()> slave, master;
};

std::vector<Configuration> configurations() {
  return {
      {"rotated cube inside (3D)",
       [] { return coapt::mesh::structured_box(0, 0, 0, 1, 1, 1, 10, 10, 10); },
       [] {
         Mesh m = coapt::mesh::structured_box(0.25, 0.25, 0.25, 0.75, 0.75, 0.75, 6, 6, 6);
         m = coapt::testing::rotated(std::move(m), 0.7, {1, 2, 3});
         return m;
       }},
      {"shifted, partly inside (3D)",
       [] { return coapt::mesh::structured_box(0, 0, 0, 1, 1, 1, 7, 6, 8); },
       [] { return coapt::mesh::structured_box(0.3, -0.2, 0.1, 1.4, 0.7, 0.9, 6, 8, 5); }},
      {"rotated, partly inside (2D)",
       [] { return coapt::mesh::structured_rectangle(0, 0, 1, 1, 16, 14); },
       [] {
         Mesh m = coapt::mesh::structured_rectangle(0.2, 0.3, 1.3, 1.2, 23, 17);
         m = coapt::testing::rotated(std::move(m), 0.4, {0, 0, 1});
         return m;
       }},
  };
}

Mesh distributed(const Mesh& whole, Partitioner partitioner) {
  return coapt::mesh::distribute(coapt::rank_of(kWorld) == 0 ? whole : Mesh(), kWorld, partitioner);
}

double linear(const double* x, int dim) {
  return 0.3 + 1.7 * x[0] - 0.9 * x[1] + (dim == 3 ? 0.6 * x[2] : 0.0);
}

/// original number of each global vertex (every rank gets the whole table).
std::vector<std::int64_t> original_numbers(const Mesh& m) {
  std::vector<std::int64_t> pairs;
  for (int v = 0; v < m.n_owned_vertices; ++v) {
    pairs.push_back(m.global_vertex[v]);
    pairs.push_back(m.original_vertex[v]);
  }
  int n = static_cast<int>(pairs.size()), size = coapt::size_of(m.comm);
  std::vector<int> counts(size), displacements(size, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, m.comm);
  for (int r = 1; r < size; ++r) displacements[r] = displacements[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(static_cast<std::size_t>(displacements.back() + counts.back()));
  MPI_Allgatherv(pairs.data(), n, MPI_INT64_T, all.data(), counts.data(), displacements.data(),
                 MPI_INT64_T, m.comm);
  std::vector<std::int64_t> table(static_cast<std::size_t>(m.n_global_vertices), -1);
  for (std::size_t i = 0; i < all.size(); i += 2) table[all[i]] = all[i + 1];
  return table;
}

using Entries = std::map<std::pair<std::int64_t, std::int64_t>, double>;

/// B's entries keyed by original (slave, master) vertex numbers, gathered on every rank.
Entries entries_by_original(const VariationalTransfer& t, const Mesh& slave, const Mesh& master) {
  const auto slave_original = original_numbers(slave), master_original = original_numbers(master);
  std::vector<double> local;  // triplets as doubles (numbers are small)
  PetscInt lo = 0, hi = 0;
  MatGetOwnershipRange(t.coupling(), &lo, &hi);
  for (PetscInt r = lo; r < hi; ++r) {
    PetscInt n = 0;
    const PetscInt* columns = nullptr;
    const PetscScalar* values = nullptr;
    MatGetRow(t.coupling(), r, &n, &columns, &values);
    for (PetscInt e = 0; e < n; ++e) {
      local.push_back(static_cast<double>(slave_original[r]));
      local.push_back(static_cast<double>(master_original[columns[e]]));
      local.push_back(values[e]);
    }
    MatRestoreRow(t.coupling(), r, &n, &columns, &values);
  }
  const MPI_Comm comm = slave.comm;
  int n = static_cast<int>(local.size()), size = coapt::size_of(comm);
  std::vector<int> counts(size), displacements(size, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < size; ++r) displacements[r] = displacements[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displacements.back() + counts.back()));
  MPI_Allgatherv(local.data(), n, MPI_DOUBLE, all.data(), counts.data(), displacements.data(),
                 MPI_DOUBLE, comm);
  Entries entries;
  for (std::size_t i = 0; i < all.size(); i += 3)
    entries[{static_cast<std::int64_t>(all[i]), static_cast<std::int64_t>(all[i + 1])}] +=
        all[i + 2];
  return entries;
}

/// Partition-independent figures of a transfer.
struct Figures {
  double sum = 0, frobenius = 0, d_sum = 0, linear_error = 0;
  double cell_covered = 0;  ///< Σ over the owned slave cells of |T| × its covered fraction
  PetscInt constrained = 0;
  std::int64_t pairs = 0;
};

Figures figures_of(const VariationalTransfer& t, const Mesh& slave, const Mesh& master) {
  Figures f;
  OwnedVec ones = t.create_master_vector(), product = t.create_slave_vector();
  VecSet(ones, 1.0);
  MatMult(t.coupling(), ones, product);
  VecSum(product, &f.sum);
  MatNorm(t.coupling(), NORM_FROBENIUS, &f.frobenius);
  VecSum(t.dual_mass(), &f.d_sum);
  f.constrained = t.n_constrained();
  OwnedVec field = t.create_master_vector(), result = t.create_slave_vector();
  PetscScalar* x = nullptr;
  VecGetArray(field, &x);
  for (int v = 0; v < master.n_owned_vertices; ++v)
    x[v] = linear(master.point(v).data(), master.dim);
  VecRestoreArray(field, &x);
  t.apply_transfer(field, result);
  const PetscScalar* y = nullptr;
  VecGetArrayRead(result, &y);
  for (PetscInt row : t.constrained_rows()) {
    const int v = static_cast<int>(row - slave.vertex_offset);
    f.linear_error =
        std::max(f.linear_error, std::fabs(y[v] - linear(slave.point(v).data(), slave.dim)));
  }
  VecRestoreArrayRead(result, &y);
  MPI_Allreduce(MPI_IN_PLACE, &f.linear_error, 1, MPI_DOUBLE, MPI_MAX, slave.comm);
  f.pairs = t.statistics().intersecting_pairs;
  MPI_Allreduce(MPI_IN_PLACE, &f.pairs, 1, MPI_INT64_T, MPI_SUM, slave.comm);
  for (int c = 0; c < slave.n_owned_cells; ++c)
    f.cell_covered += t.cell_coverage()[c] * std::fabs(coapt::mesh::cell_signed_measure(slave, c));
  MPI_Allreduce(MPI_IN_PLACE, &f.cell_covered, 1, MPI_DOUBLE, MPI_SUM, slave.comm);
  return f;
}

TEST(TransferOperatorsParallel, IndependentPartitionsGiveTheSerialOperators) {
  for (const Configuration& configuration : configurations()) {
    SCOPED_TRACE(configuration.name);
    const Mesh whole_slave = configuration.slave(), whole_master = configuration.master();
    // reference: the whole meshes on one rank (every rank builds it on MPI_COMM_SELF)
    VariationalTransfer serial(whole_slave, whole_master);
    const Figures reference = figures_of(serial, whole_slave, whole_master);
    const Entries reference_entries = entries_by_original(serial, whole_slave, whole_master);

    const Mesh slave = distributed(whole_slave, Partitioner::metis);
    const Mesh master = distributed(whole_master, Partitioner::blocks);
    VariationalTransfer parallel(slave, master);
    const Figures f = figures_of(parallel, slave, master);

    EXPECT_NEAR(f.sum, reference.sum, 1e-12 * reference.sum);
    EXPECT_NEAR(f.d_sum, reference.sum, 1e-12 * reference.sum);
    EXPECT_NEAR(f.cell_covered, reference.sum, 1e-12 * reference.sum);  // each cell once
    EXPECT_NEAR(f.frobenius, reference.frobenius, 1e-12 * reference.frobenius);
    EXPECT_EQ(f.constrained, reference.constrained);
    EXPECT_GT(f.constrained, 0);
    EXPECT_EQ(f.pairs, reference.pairs);  // each pair integrated once, by one rank
    EXPECT_LT(f.linear_error, 1e-12);
    EXPECT_LT(reference.linear_error, 1e-12);

    // entry by entry, through the original numbering
    const Entries entries = entries_by_original(parallel, slave, master);
    EXPECT_EQ(entries.size(), reference_entries.size());
    double largest = 0, worst = 0;
    for (const auto& [key, value] : reference_entries)
      largest = std::max(largest, std::fabs(value));
    for (const auto& [key, value] : reference_entries) {
      const auto found = entries.find(key);
      ASSERT_NE(found, entries.end()) << "missing entry " << key.first << ", " << key.second;
      worst = std::max(worst, std::fabs(found->second - value));
    }
    EXPECT_LT(worst, 1e-13 * largest);
    if (std::getenv("COAPT_TRANSFER_REPORT") && coapt::rank_of(kWorld) == 0)
      std::printf(
          "[transfer] %s on %d rank(s): %lld pairs, sum B %.17g (serial %.17g), |B|_F rel. "
          "difference %.1e, constrained %d, T linear error %.1e, largest entry difference "
          "%.1e (relative to max |B_ij|)\n",
          configuration.name.c_str(), coapt::size_of(kWorld), static_cast<long long>(f.pairs),
          f.sum, reference.sum, std::fabs(f.frobenius - reference.frobenius) / reference.frobenius,
          static_cast<int>(f.constrained), f.linear_error, worst / largest);
  }
}

TEST(TransferOperatorsParallel, MovingMasterReusesTheSearch) {
  Mesh whole_master = coapt::mesh::structured_box(0.25, 0.25, 0.25, 0.75, 0.75, 0.75, 5, 5, 5);
  whole_master = coapt::testing::rotated(std::move(whole_master), 0.3, {1, 1, 2});
  const Mesh slave =
      distributed(coapt::mesh::structured_box(0, 0, 0, 1, 1, 1, 7, 7, 7), Partitioner::metis);
  Mesh master = distributed(whole_master, Partitioner::blocks);
  VariationalTransfer moving(slave, master, TransferOptions{.search_margin = 0.02});
  for (int step = 1; step <= 2; ++step) {
    // the same smooth motion on owned and ghost vertices (a function of the position)
    for (int v = 0; v < master.n_vertices(); ++v) {
      double* x = master.coordinates.data() + 3 * v;
      const double dx = 0.006 + 0.002 * std::sin(5 * x[1]), dy = 0.002 * std::cos(3 * x[2]);
      x[0] += dx;
      x[1] += dy;
    }
    moving.update_master(master);
    EXPECT_FALSE(moving.statistics().search.full);
    VariationalTransfer fresh(slave, master);
    const Figures a = figures_of(moving, slave, master), b = figures_of(fresh, slave, master);
    EXPECT_NEAR(a.sum, b.sum, 1e-13 * b.sum);
    EXPECT_NEAR(a.frobenius, b.frobenius, 1e-13 * b.frobenius);
    EXPECT_EQ(a.constrained, b.constrained);
    EXPECT_EQ(a.pairs, b.pairs);
    EXPECT_LT(a.linear_error, 1e-12);
  }
}

// Re-assembly after the master moved: (a) a tiny motion keeps the search and the matrix
// pattern, (b) a motion within the margin that changes the intersecting pairs keeps the
// search but re-creates B, (c) a motion past the margin redoes the search. Each time B, D and
// the constrained set must be those of a fresh assembly, entry by entry.
TEST(TransferOperatorsParallel, ReassemblyMatchesAFreshAssemblyWhenThePatternChanges) {
  Mesh whole_master = coapt::mesh::structured_box(0.25, 0.25, 0.25, 0.75, 0.75, 0.75, 5, 5, 5);
  whole_master = coapt::testing::rotated(std::move(whole_master), 0.3, {1, 1, 2});
  const Mesh slave =
      distributed(coapt::mesh::structured_box(0, 0, 0, 1, 1, 1, 7, 7, 7), Partitioner::metis);
  Mesh master = distributed(whole_master, Partitioner::blocks);
  VariationalTransfer moving(slave, master, TransferOptions{.search_margin = 0.02});
  EXPECT_FALSE(moving.statistics().pattern_reused);
  struct Motion {
    const char* name;
    double shift;
    bool full_search, pattern_reused;
  };
  const Motion motions[] = {{"tiny motion", 1e-9, false, true},
                            {"within the margin, new pairs", 0.012, false, false},
                            {"past the margin", 0.09, true, false}};
  for (const Motion& motion : motions) {
    SCOPED_TRACE(motion.name);
    for (int v = 0; v < master.n_vertices(); ++v) {
      double* x = master.coordinates.data() + 3 * v;
      x[0] += motion.shift;
      x[1] -= 0.5 * motion.shift;
      x[2] += 0.25 * motion.shift;
    }
    moving.update_master(master);
    EXPECT_EQ(moving.statistics().search.full, motion.full_search);
    EXPECT_EQ(moving.statistics().pattern_reused, motion.pattern_reused);
    VariationalTransfer fresh(slave, master);
    const Figures a = figures_of(moving, slave, master), b = figures_of(fresh, slave, master);
    EXPECT_NEAR(a.sum, b.sum, 1e-13 * b.sum);
    EXPECT_NEAR(a.d_sum, b.d_sum, 1e-13 * b.d_sum);
    EXPECT_EQ(a.constrained, b.constrained);
    EXPECT_EQ(a.pairs, b.pairs);
    EXPECT_LT(a.linear_error, 1e-12);
    EXPECT_EQ(moving.constrained_rows(), fresh.constrained_rows());
    const Entries entries = entries_by_original(moving, slave, master);
    const Entries reference = entries_by_original(fresh, slave, master);
    EXPECT_EQ(entries.size(), reference.size());
    double largest = 0, worst = 0;
    for (const auto& [key, value] : reference) largest = std::max(largest, std::fabs(value));
    for (const auto& [key, value] : reference) {
      const auto found = entries.find(key);
      ASSERT_NE(found, entries.end()) << "missing entry " << key.first << ", " << key.second;
      worst = std::max(worst, std::fabs(found->second - value));
    }
    EXPECT_LT(worst, 1e-13 * largest);
    // D entry by entry (same slave layout)
    OwnedVec difference = moving.create_slave_vector();
    VecWAXPY(difference, -1.0, fresh.dual_mass(), moving.dual_mass());
    double d_worst = 0, d_largest = 0;
    VecNorm(difference, NORM_INFINITY, &d_worst);
    VecNorm(fresh.dual_mass(), NORM_INFINITY, &d_largest);
    EXPECT_LT(d_worst, 1e-13 * d_largest);
    if (std::getenv("COAPT_TRANSFER_REPORT") && coapt::rank_of(kWorld) == 0)
      std::printf(
          "[transfer] re-assembly, %s on %d rank(s): full search %d, pattern reused %d, "
          "%lld pairs, re-assembly %.4f s (search %.4f, intersection %.4f, assembly "
          "%.4f), largest entry difference %.1e\n",
          motion.name, coapt::size_of(kWorld), moving.statistics().search.full,
          moving.statistics().pattern_reused, static_cast<long long>(a.pairs),
          moving.statistics().search_seconds + moving.statistics().intersection_seconds +
              moving.statistics().assembly_seconds,
          moving.statistics().search_seconds, moving.statistics().intersection_seconds,
          moving.statistics().assembly_seconds, worst / largest);
  }
}

}  // namespace
