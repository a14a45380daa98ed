// coapt-bench fluid: the stabilised P1-P1 Navier–Stokes operator on a 3D box channel
// [0, 4] × [0, 1] × [0, 1] with 4n × n × n cubes of 6 tetrahedra: assembly of the residual and
// of residual + Jacobian (tets/s per rank, the mean of `repeat`), then one steady Newton solve
// with the linear solver of the options (default GMRES + Schur fieldsplit, -fluid_pc_type lu
// for the direct one): wall time, Newton and Krylov iterations.
//
// Flow: inflow 16 U y z (1 − y)(1 − z) at x = 0 (U = 1), no-slip on the four side walls,
// do-nothing outlet at x = 4; ρ = 1, μ = 0.05 (Re = ρ U_mean · 1 / μ ≈ 9).

#include <algorithm>
#include <memory>

#include "bench_common.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fluid/navier_stokes.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace coapt::bench {
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

/// Fixes the velocity on the inlet (x = 0) and the side walls: inflow profile there, 0 on the
/// walls (walls win on shared vertices).
void set_channel_conditions(const mesh::Mesh& mesh, fluid::NavierStokes& fluid) {
  constexpr int n = 4;
  // Tags of structured_box: left 1, right 2, front 3, back 4, bottom 5, top 6.
  std::vector<char> kind(static_cast<std::size_t>(mesh.n_owned_vertices), 0);  // 1 in, 2 wall
  for (int f = 0; f < mesh.n_facets(); ++f)
    for (int a = 0; a < 3; ++a) {
      const int v = mesh.facets[static_cast<std::size_t>(f) * 3 + a];
      const int tag = mesh.facet_tags[f];
      if (v >= mesh.n_owned_vertices || tag == 2) continue;
      kind[v] = std::max<char>(kind[v], tag == 1 ? 1 : 2);
    }
  std::vector<PetscInt> dofs;
  for (int v = 0; v < mesh.n_owned_vertices; ++v) {
    if (!kind[v]) continue;
    const double y = mesh.point(v)[1], z = mesh.point(v)[2];
    const double u = kind[v] == 1 ? 16 * y * z * (1 - y) * (1 - z) : 0.0;
    COAPT_PETSC_CHECK(VecSetValue(fluid.state(), mesh.global_vertex[v] * n, u, INSERT_VALUES));
    for (int i = 0; i < 3; ++i) dofs.push_back(mesh.global_vertex[v] * n + i);
  }
  COAPT_PETSC_CHECK(VecAssemblyBegin(fluid.state()));
  COAPT_PETSC_CHECK(VecAssemblyEnd(fluid.state()));
  fem::update_ghosts(fluid.state());
  fluid.set_dirichlet_dofs(std::move(dofs));
}

}  // namespace

io::Json fluid(const Context& context, const FluidBenchOptions& options) {
  const MPI_Comm comm = context.comm();
  mesh::Mesh whole;
  if (context.rank() == 0)
    whole = mesh::structured_box(0, 0, 0, 4, 1, 1, 4 * options.n, options.n, options.n);
  const auto mesh = mesh::distribute(whole, comm);
  whole = mesh::Mesh();
  long long max_owned = mesh.n_owned_cells;
  MPI_Allreduce(MPI_IN_PLACE, &max_owned, 1, MPI_LONG_LONG, MPI_MAX, comm);
  log::info(
      "fluid: channel [0, 4] x [0, 1] x [0, 1], n = {}: {} tetrahedra, {} vertices ({} dofs) on {} "
      "rank(s) (at most {} cells per rank)",
      options.n, mesh.n_global_cells, mesh.n_global_vertices, 4 * mesh.n_global_vertices,
      context.size(), max_owned);

  fluid::FluidParameters parameters;
  parameters.density = 1.0;
  parameters.viscosity = 0.05;
  std::unique_ptr<fluid::NavierStokes> operator_;
  const double setup = timed(comm, [&] {
    operator_ = std::make_unique<fluid::NavierStokes>(mesh, parameters);
    set_channel_conditions(mesh, *operator_);
  });
  auto& flow = *operator_;
  log::info("linear solver: {}", flow.describe_solver());
  const fluid::TimeLevel steady;
  OwnedVec work, direction;
  COAPT_PETSC_CHECK(VecDuplicate(flow.state(), work.out()));
  COAPT_PETSC_CHECK(VecDuplicate(flow.state(), direction.out()));
  COAPT_PETSC_CHECK(VecSet(direction, 1.0));
  double residual_seconds = 0, jacobian_seconds = 0;
  for (int i = 0; i < options.repeat; ++i) {
    residual_seconds += timed(comm, [&] { flow.residual(steady, work); });
    // Residual + Jacobian assembly and one product with it.
    jacobian_seconds += timed(comm, [&] { flow.jacobian_action(steady, direction, work); });
  }
  residual_seconds /= options.repeat;
  jacobian_seconds /= options.repeat;
  const double per_rank = static_cast<double>(max_owned);
  log::info(
      "assembly: residual {:.3f} s ({:.3g} tets/s per rank), residual + Jacobian {:.3f} s ({:.3g} "
      "tets/s per rank)",
      residual_seconds, per_rank / residual_seconds, jacobian_seconds, per_rank / jacobian_seconds);

  fluid::NewtonReport report;
  const double solve_seconds = timed(comm, [&] { report = flow.solve(steady, "bench"); });
  log::info("steady Newton solve: {:.2f} s, {} Newton steps, {} Krylov iterations", solve_seconds,
            report.iterations, report.linear_iterations);

  io::Json figures = io::Json::object();
  figures["benchmark"] = "fluid";
  figures["n"] = options.n;
  figures["ranks"] = context.size();
  figures["tets"] = static_cast<std::int64_t>(mesh.n_global_cells);
  figures["dofs"] = static_cast<std::int64_t>(4 * mesh.n_global_vertices);
  figures["linear_solver"] = flow.describe_solver();
  figures["setup_seconds"] = setup;
  figures["residual_seconds"] = residual_seconds;
  figures["residual_tets_per_second_per_rank"] = per_rank / residual_seconds;
  figures["jacobian_seconds"] = jacobian_seconds;
  figures["jacobian_tets_per_second_per_rank"] = per_rank / jacobian_seconds;
  figures["solve_seconds"] = solve_seconds;
  figures["newton_iterations"] = report.iterations;
  figures["krylov_iterations"] = report.linear_iterations;
  figures["seconds_per_newton_step"] = solve_seconds / std::max(1, report.iterations);
  figures["krylov_per_newton_step"] =
      static_cast<double>(report.linear_iterations) / std::max(1, report.iterations);
  return figures;
}

}  // namespace coapt::bench
