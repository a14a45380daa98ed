// coapt-bench assembly: tets per second per rank for the P1 Laplacian and the P1 elasticity
// stiffness on the unit cube with n^3 * 6 tetrahedra: first assembly (COO pattern, matrix
// creation and values) and re-assembly into the existing matrix (kernels + insertion).

#include <sys/resource.h>

#include <algorithm>

#include "bench_common.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/kernels.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace coapt::bench {

double peak_rss_mb(MPI_Comm comm) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  double mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
  MPI_Allreduce(MPI_IN_PLACE, &mb, 1, MPI_DOUBLE, MPI_MAX, comm);
  return mb;
}

namespace {

/// Slowest rank's time of `work` (collective).
template <class Work>
double timed(MPI_Comm comm, Work&& work) {
  MPI_Barrier(comm);
  const double start = MPI_Wtime();
  work();
  double seconds = MPI_Wtime() - start;
  MPI_Allreduce(MPI_IN_PLACE, &seconds, 1, MPI_DOUBLE, MPI_MAX, comm);
  return seconds;
}

}  // namespace

io::Json assembly(const Context& context, const AssemblyOptions& options) {
  const MPI_Comm comm = context.comm();
  mesh::Mesh whole;
  if (context.rank() == 0)
    whole = mesh::structured_box(0, 0, 0, 1, 1, 1, options.n, options.n, options.n);
  const auto mesh = mesh::distribute(whole, comm);
  whole = mesh::Mesh();
  long long max_owned = mesh.n_owned_cells;
  MPI_Allreduce(MPI_IN_PLACE, &max_owned, 1, MPI_LONG_LONG, MPI_MAX, comm);
  log::info(
      "assembly: unit cube, n = {}: {} tetrahedra, {} vertices on {} rank(s) (at most {} per "
      "rank), {} re-assemblies",
      options.n, mesh.n_global_cells, mesh.n_global_vertices, context.size(), max_owned,
      options.repeat);

  auto laplacian = [&](int c, double* element) {
    const auto vertices = mesh.cell(c);
    const double* points[4] = {mesh.point(vertices[0]).data(), mesh.point(vertices[1]).data(),
                               mesh.point(vertices[2]).data(), mesh.point(vertices[3]).data()};
    fem::element_laplacian<3>(points, element);
  };
  auto elasticity = [&](int c, double* element) {
    const auto vertices = mesh.cell(c);
    const double* points[4] = {mesh.point(vertices[0]).data(), mesh.point(vertices[1]).data(),
                               mesh.point(vertices[2]).data(), mesh.point(vertices[3]).data()};
    fem::element_elasticity<3>(points, 1.0, 1.0, element);
  };

  io::Json figures = io::Json::object();
  figures["benchmark"] = "assembly";
  figures["n"] = options.n;
  figures["ranks"] = context.size();
  figures["tets"] = static_cast<std::int64_t>(mesh.n_global_cells);
  const double per_rank = static_cast<double>(max_owned);
  auto measure = [&](const std::string& name, int components, auto&& kernel) {
    std::unique_ptr<fem::P1Matrix> matrix;
    const double first = timed(comm, [&] {
      matrix = std::make_unique<fem::P1Matrix>(mesh, components);
      matrix->assemble(kernel);
    });
    double total = 0;
    for (int i = 0; i < options.repeat; ++i)
      total += timed(comm, [&] { matrix->assemble(kernel); });
    const double again = total / options.repeat;
    log::info(
        "{}: first assembly {:.3f} s ({:.3g} tets/s per rank), re-assembly {:.3f} s ({:.3g} tets/s "
        "per rank)",
        name, first, per_rank / first, again, per_rank / again);
    figures[name + "_first_seconds"] = first;
    figures[name + "_first_tets_per_second_per_rank"] = per_rank / first;
    figures[name + "_reassembly_seconds"] = again;
    figures[name + "_reassembly_tets_per_second_per_rank"] = per_rank / again;
  };
  measure("laplacian", 1, laplacian);
  measure("elasticity", 3, elasticity);
  return figures;
}

}  // namespace coapt::bench
