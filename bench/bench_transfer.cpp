// coapt-bench transfer: the variational transfer operators (search, intersection, assembly)
// between the unit cube with n^3 * 6 tetrahedra (the slave, partitioned by METIS) and a
// master partitioned in blocks of its cell order (so the partitions do not align):
//   jitter   the same cube with its interior vertices moved by up to ±0.1 h per coordinate
//            (deterministic pseudo-random, from the vertex number);
//   rotated  a cube of side 0.55 centred at (0.5, 0.5, 0.5), rotated about a generic axis,
//            meshed with about the same h.
// Then the master is moved by 0.01 h (smooth field) and the operators are re-assembled with
// the search structure reused (margin 0.02 h), timed separately.

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "bench_common.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"
#include "coapt/transfer/operators.hpp"

namespace coapt::bench {

namespace {

/// Uniform in [−1, 1] from an integer (splitmix64).
double hash_uniform(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return 2.0 * static_cast<double>(x >> 11) / 9007199254740992.0 - 1.0;
}

mesh::Mesh jittered_cube(int n) {
  mesh::Mesh m = mesh::structured_box(0, 0, 0, 1, 1, 1, n, n, n);
  const double h = 1.0 / n;
  for (int v = 0; v < m.n_vertices(); ++v) {
    double* x = m.coordinates.data() + 3 * v;
    bool interior = true;
    for (int k = 0; k < 3; ++k) interior = interior && x[k] > 0.5 * h && x[k] < 1 - 0.5 * h;
    if (!interior) continue;
    for (int k = 0; k < 3; ++k)
      x[k] += 0.1 * h * hash_uniform(3 * static_cast<std::uint64_t>(v) + k);
  }
  return m;
}

mesh::Mesh rotated_cube(int n) {
  const double side = 0.55;
  const int m_cells = std::max(1, static_cast<int>(std::lround(side * n)));
  mesh::Mesh m =
      mesh::structured_box(0.5 - side / 2, 0.5 - side / 2, 0.5 - side / 2, 0.5 + side / 2,
                           0.5 + side / 2, 0.5 + side / 2, m_cells, m_cells, m_cells);
  double u[3] = {1.0, 2.0, 3.0};
  const double norm = std::sqrt(14.0);
  for (double& a : u) a /= norm;
  const double angle = 0.5, c = std::cos(angle), s = std::sin(angle);
  const double r[3][3] = {{c + u[0] * u[0] * (1 - c), u[0] * u[1] * (1 - c) - u[2] * s,
                           u[0] * u[2] * (1 - c) + u[1] * s},
                          {u[1] * u[0] * (1 - c) + u[2] * s, c + u[1] * u[1] * (1 - c),
                           u[1] * u[2] * (1 - c) - u[0] * s},
                          {u[2] * u[0] * (1 - c) - u[1] * s, u[2] * u[1] * (1 - c) + u[0] * s,
                           c + u[2] * u[2] * (1 - c)}};
  for (int v = 0; v < m.n_vertices(); ++v) {
    double* x = m.coordinates.data() + 3 * v;
    const double y[3] = {x[0] - 0.5, x[1] - 0.5, x[2] - 0.5};
    for (int i = 0; i < 3; ++i) x[i] = 0.5 + r[i][0] * y[0] + r[i][1] * y[1] + r[i][2] * y[2];
  }
  return m;
}

/// Resident memory of this process now [MB] (VmRSS).
double current_rss_mb() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  char line[256];
  double mb = 0;
  while (f && std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "VmRSS: %lf", &mb) == 1) break;
  if (f) std::fclose(f);
  return mb / 1024.0;
}

double max_over_ranks(MPI_Comm comm, double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm);
  return value;
}
std::int64_t sum_over_ranks(MPI_Comm comm, std::int64_t value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_INT64_T, MPI_SUM, comm);
  return value;
}

}  // namespace

io::Json transfer(const Context& context, const TransferBenchOptions& options) {
  const MPI_Comm comm = context.comm();
  const int ranks = context.size();
  if (options.case_name != "jitter" && options.case_name != "rotated")
    throw InputError("transfer: --case must be jitter or rotated, not '" + options.case_name + "'");
  const double h = 1.0 / options.n;
  mesh::Mesh whole_slave, whole_master;
  double overlap = 0;  // |S ∩ M|, exact
  if (options.case_name == "jitter") {
    overlap = 1.0;
  } else {
    overlap = 0.55 * 0.55 * 0.55;
  }
  if (context.rank() == 0) {
    whole_slave = mesh::structured_box(0, 0, 0, 1, 1, 1, options.n, options.n, options.n);
    whole_master =
        options.case_name == "jitter" ? jittered_cube(options.n) : rotated_cube(options.n);
  }
  const mesh::Mesh slave = mesh::distribute(whole_slave, comm, mesh::Partitioner::metis);
  mesh::Mesh master = mesh::distribute(whole_master, comm, mesh::Partitioner::blocks);
  whole_slave = mesh::Mesh();
  whole_master = mesh::Mesh();
  log::info("transfer ({}): slave {} tetrahedra, master {} tetrahedra, {} rank(s)",
            options.case_name, slave.n_global_cells, master.n_global_cells, ranks);

  const double rss_before = current_rss_mb();
  transfer::TransferOptions transfer_options;
  transfer_options.search_margin = 0.02 * h;
  MPI_Barrier(comm);
  double start = MPI_Wtime();
  transfer::VariationalTransfer operators(slave, master, transfer_options);
  const double first_seconds = max_over_ranks(comm, MPI_Wtime() - start);

  io::Json figures = io::Json::object();
  figures["benchmark"] = "transfer";
  figures["case"] = options.case_name;
  figures["n"] = options.n;
  figures["ranks"] = ranks;
  figures["slave_tets"] = static_cast<std::int64_t>(slave.n_global_cells);
  figures["master_tets"] = static_cast<std::int64_t>(master.n_global_cells);
  auto record = [&](const std::string& prefix, double wall) {
    const transfer::TransferStatistics& s = operators.statistics();
    std::int64_t local_pairs = s.intersecting_pairs;
    const std::int64_t pairs = sum_over_ranks(comm, local_pairs);
    const std::int64_t max_pairs =
        static_cast<std::int64_t>(max_over_ranks(comm, static_cast<double>(local_pairs)));
    const double search = max_over_ranks(comm, s.search_seconds);
    const double intersection = max_over_ranks(comm, s.intersection_seconds);
    const double assembly = max_over_ranks(comm, s.assembly_seconds);
    const double per_rank = static_cast<double>(pairs) / ranks;
    figures[prefix + "intersecting_pairs"] = pairs;
    figures[prefix + "max_pairs_on_a_rank"] = max_pairs;
    figures[prefix + "candidate_pairs"] = sum_over_ranks(comm, s.search.candidate_pairs);
    figures[prefix + "filtered_pairs"] = sum_over_ranks(comm, s.search.pairs);
    figures[prefix + "front_fallbacks"] = sum_over_ranks(comm, s.search.front_fallbacks);
    figures[prefix + "received_master_cells"] =
        sum_over_ranks(comm, s.search.received_master_cells);
    figures[prefix + "search_seconds"] = search;
    figures[prefix + "exchange_seconds"] = max_over_ranks(comm, s.search.exchange_seconds);
    figures[prefix + "grid_seconds"] = max_over_ranks(comm, s.search.grid_seconds);
    figures[prefix + "query_seconds"] = max_over_ranks(comm, s.search.query_seconds);
    figures[prefix + "intersection_seconds"] = intersection;
    figures[prefix + "assembly_seconds"] = assembly;
    figures[prefix + "total_seconds"] = wall;
    figures[prefix + "pairs_per_second_per_rank"] = per_rank / wall;
    figures[prefix + "intersection_pairs_per_second_per_rank"] = per_rank / intersection;
    figures[prefix + "search_reused"] = !s.search.full;
    figures[prefix + "pattern_reused"] = s.pattern_reused;
    log::info(
        "{}{} intersecting pairs ({} pairs tested by the front, {} slave cells fell back to the "
        "grid); search {:.3f} s, front + intersection {:.3f} s, assembly {:.3f} s, total {:.3f} s: "
        "{:.3g} pairs/s per rank ({:.3g} in the front + intersection alone); search reused: {}, "
        "pattern reused: {}",
        prefix, pairs, figures[prefix + "candidate_pairs"].dump(),
        figures[prefix + "front_fallbacks"].dump(), search, intersection, assembly, wall,
        per_rank / wall, per_rank / intersection, !s.search.full, s.pattern_reused);
  };
  record("", first_seconds);
  const double rss_after = current_rss_mb();
  figures["rss_before_operators_mb"] = max_over_ranks(comm, rss_before);
  figures["rss_after_operators_mb"] = max_over_ranks(comm, rss_after);
  figures["search_memory_mb"] = max_over_ranks(
      comm, static_cast<double>(operators.statistics().search.memory_bytes) / 1048576.0);
  log::info("resident memory before the operators {:.1f} MB, after {:.1f} MB (rank 0)", rss_before,
            rss_after);
  // sanity: Σ B = |S ∩ M| and the constrained nodes
  {
    OwnedVec ones = operators.create_master_vector(), sums = operators.create_slave_vector();
    VecSet(ones, 1.0);
    MatMult(operators.coupling(), ones, sums);
    PetscScalar total = 0;
    VecSum(sums, &total);
    figures["overlap_relative_error"] = std::fabs(total - overlap) / overlap;
    figures["constrained_nodes"] = static_cast<std::int64_t>(operators.n_constrained());
  }

  // Move the master by at most 0.01 h (the same smooth field on owned and ghost vertices).
  for (int v = 0; v < master.n_vertices(); ++v) {
    double* x = master.coordinates.data() + 3 * v;
    const double a = 0.01 * h;
    const double d[3] = {a * std::sin(6.1 * x[1] + 0.3), a * std::sin(5.3 * x[2] + 0.7),
                         a * std::sin(4.7 * x[0] + 1.1)};
    for (int k = 0; k < 3; ++k) x[k] += d[k];
  }
  MPI_Barrier(comm);
  start = MPI_Wtime();
  operators.update_master(master);
  const double again_seconds = max_over_ranks(comm, MPI_Wtime() - start);
  record("reassembly_", again_seconds);
  return figures;
}

}  // namespace coapt::bench
