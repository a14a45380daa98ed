#include "coapt/fluid/flow_problem.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>

#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/core/progress.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fluid/kernels.hpp"
#include "coapt/fluid/navier_stokes.hpp"
#include "coapt/lumped/windkessel.hpp"
#include "coapt/mesh/mesh_input.hpp"

namespace coapt::fluid {
namespace {

using config::Bounds;

/// One entry of `boundary:`; later entries override earlier ones at shared vertices.
struct BoundaryCondition {
  enum class Type { velocity, no_slip, outflow };
  enum class Profile { constant, parabolic, radial };
  enum class Waveform { none, sinusoid, table };
  std::string group;
  std::string where;  ///< file:line of the entry
  Type type = Type::no_slip;
  Profile profile = Profile::constant;
  std::vector<double> value;     ///< velocity (peak for parabolic) [m/s]
  std::vector<double> from, to;  ///< parabolic: the two ends of the profile [m]
  double ramp_time = 0;          ///< > 0: value × (1 − cos(π min(t/T, 1)))/2 [s]
  std::vector<double> centre;    ///< radial: the axis point of the inlet plane [m]
  double radius = 0;             ///< radial: value × (1 − r²/radius²) [m]
  Waveform waveform = Waveform::none;
  double amplitude = 0;                ///< sinusoid: value × (1 + a sin(2πt/T))
  double period = 0;                   ///< sinusoid, table: T [s] (table: 0 = not periodic)
  std::vector<double> times, factors;  ///< table: value × factor(t), linear in between
};

/// An entry of `outlets:`: the pressure on a facet group, fixed or from a Windkessel.
struct OutletCondition {
  enum class Type { do_nothing, traction, windkessel };
  std::string group;
  std::string where;
  Type type = Type::do_nothing;
  double pressure = 0;  ///< traction: P [Pa]
  lumped::WindkesselParameters windkessel;
  double backflow = 0;  ///< β
};

struct Benchmark {
  std::string type = "none";  ///< none | cavity | cylinder | windkessel
  // windkessel: the outlet whose RCR relation is checked, the period of the inflow
  std::string outlet;
  double period = 0;
  // cavity: reference centreline tables (u(0.5, y), v(x, 0.5)), lid speed
  std::vector<double> reference_y, reference_u, reference_x, reference_v;
  int profile_points = 129;
  // cylinder: body group, normalisation, pressure probes, reference values
  std::string body;
  double mean_velocity = 1, diameter = 1;
  std::vector<double> pressure_points;  ///< x_A, y_A, x_B, y_B: Δp = p(A) − p(B)
  double reference_drag = 0, reference_lift = 0, reference_pressure_difference = 0;
};

struct Parameters {
  mesh::MeshInput mesh;
  FluidParameters fluid;
  std::vector<BoundaryCondition> boundary;
  std::vector<OutletCondition> outlets;
  bool has_pressure_reference = false;
  std::vector<double> pressure_reference;  ///< the vertex nearest to it gets p = 0
  bool steady = true;
  double end_time = 0, time_step = 0;
  Benchmark benchmark;
  bool write_vtk = true;
};

Parameters read(const config::Section& root) {
  Parameters p;
  p.mesh = mesh::MeshInput::read(root.section("mesh", "the mesh"), root.case_directory());
  auto fluid = root.section("fluid", "fluid properties and solver settings");
  p.fluid.density = fluid.get<double>("density", 1.0, {"kg/m^3", "density ρ", Bounds::positive()});
  p.fluid.viscosity =
      fluid.get<double>("viscosity", 1e-3, {"Pa s", "dynamic viscosity μ", Bounds::positive()});
  p.fluid.convection = fluid.get<bool>("convection", true, {"", "false: Stokes flow (no u·∇u)"});
  p.fluid.c_inverse =
      fluid.get<double>("c_inverse", kDefaultCInverse,
                        {"", "C_I of the stabilisation parameter τ_M (9: nodally exact 1D limits)",
                         Bounds::positive()});
  auto newton = fluid.section("newton", "Newton's method per step");
  p.fluid.newton_relative_tolerance = newton.get<double>(
      "relative_tolerance", 1e-8, {"", "stop when ‖R‖ ≤ rtol ‖R₀‖", Bounds::open(0, 1)});
  p.fluid.newton_absolute_tolerance = newton.get<double>(
      "absolute_tolerance", 1e-10, {"", "or when ‖R‖ ≤ atol", Bounds::non_negative()});
  p.fluid.newton_max_iterations =
      newton.get<int>("max_iterations", 25, {"", "Newton iterations", Bounds::closed(1, 1000)});

  for (const auto& entry : root.sections("boundary", "boundary conditions, in order")) {
    BoundaryCondition bc;
    bc.where = entry.where();
    bc.group = entry.require<std::string>("group", {"", "boundary group (facet physical group)"});
    const auto type = entry.choice("type", "", {"velocity", "no_slip", "outflow"},
                                   {"", "velocity | no_slip | outflow (do-nothing)"});
    bc.type = type == "velocity"  ? BoundaryCondition::Type::velocity
              : type == "no_slip" ? BoundaryCondition::Type::no_slip
                                  : BoundaryCondition::Type::outflow;
    if (bc.type == BoundaryCondition::Type::velocity) {
      bc.value = entry.require<std::vector<double>>(
          "value", {"m/s", "velocity vector (the peak for a parabolic profile)"});
      const auto profile = entry.choice(
          "profile", "constant", {"constant", "parabolic", "radial"},
          {"", "constant | parabolic (between `from` and `to`) | radial (about `centre`)"});
      if (profile == "parabolic") {
        bc.profile = BoundaryCondition::Profile::parabolic;
        bc.from = entry.require<std::vector<double>>("from", {"m", "one end of the profile"});
        bc.to = entry.require<std::vector<double>>("to", {"m", "the other end"});
      } else if (profile == "radial") {
        bc.profile = BoundaryCondition::Profile::radial;
        bc.centre = entry.require<std::vector<double>>(
            "centre", {"m", "radial: centre of the inlet (value × (1 − r²/radius²))"});
        bc.radius = entry.require<double>("radius",
                                          {"m", "radial: radius of the inlet", Bounds::positive()});
      }
      auto waveform = entry.section("waveform", "periodic factor on the value in time");
      const auto kind = waveform.choice(
          "type", "none", {"none", "sinusoid", "table"},
          {"", "none | sinusoid (1 + a sin(2πt/T)) | table (linear in time; steady runs: none)"});
      if (kind == "sinusoid") {
        bc.waveform = BoundaryCondition::Waveform::sinusoid;
        bc.amplitude = waveform.require<double>("amplitude", {"", "a of 1 + a sin(2πt/T)"});
        bc.period = waveform.require<double>("period", {"s", "period T", Bounds::positive()});
      } else if (kind == "table") {
        bc.waveform = BoundaryCondition::Waveform::table;
        bc.times = waveform.require<std::vector<double>>("times", {"s", "table times, increasing"});
        bc.factors = waveform.require<std::vector<double>>("values", {"", "factor at each time"});
        bc.period =
            waveform.get<double>("period", 0.0,
                                 {"s", "repeat the table with this period (0: hold the last value)",
                                  Bounds::non_negative()});
        if (bc.times.size() < 2 || bc.times.size() != bc.factors.size())
          waveform.fail("values", "needs at least 2 entries, as many as times");
        for (std::size_t k = 1; k < bc.times.size(); ++k)
          if (!(bc.times[k] > bc.times[k - 1])) waveform.fail("times", "must increase");
      }
      bc.ramp_time = entry.get<double>(
          "ramp_time", 0.0,
          {"s", "smooth ramp (1 − cos(πt/T))/2 up to this time (0: none)", Bounds::non_negative()});
    }
    p.boundary.push_back(std::move(bc));
  }
  if (p.boundary.empty()) root.fail("boundary", "the case needs boundary conditions");
  for (const auto& entry : root.sections("outlets", "outlet pressures (traction −P n)")) {
    OutletCondition outlet;
    outlet.where = entry.where();
    outlet.group = entry.require<std::string>("group", {"", "boundary group of the outlet"});
    const auto type = entry.choice(
        "type", "do_nothing", {"do_nothing", "traction", "windkessel"},
        {"", "do_nothing (P = 0) | traction (fixed P) | windkessel (RCR, coupled implicitly)"});
    outlet.type = type == "do_nothing" ? OutletCondition::Type::do_nothing
                  : type == "traction" ? OutletCondition::Type::traction
                                       : OutletCondition::Type::windkessel;
    if (outlet.type == OutletCondition::Type::traction)
      outlet.pressure = entry.require<double>("pressure", {"Pa", "traction: outlet pressure P"});
    if (outlet.type == OutletCondition::Type::windkessel) {
      auto w = entry.section("windkessel",
                             "RCR parameters: P = R_p Q + P_c, C dP_c/dt = Q − (P_c − P_d)/R_d");
      auto& wk = outlet.windkessel;
      wk.proximal_resistance =
          w.require<double>("proximal_resistance", {"Pa s/m^3", "R_p", Bounds::positive()});
      wk.compliance = w.require<double>("compliance", {"m^3/Pa", "C", Bounds::positive()});
      wk.distal_resistance =
          w.require<double>("distal_resistance", {"Pa s/m^3", "R_d", Bounds::positive()});
      wk.distal_pressure = w.get<double>("distal_pressure", 0.0, {"Pa", "venous pressure P_d"});
      wk.initial_pressure = w.get<double>("initial_pressure", 0.0, {"Pa", "P_c at the start"});
      wk.validate(w.path());
    }
    outlet.backflow =
        entry.get<double>("backflow", 0.2,
                          {"", "β of the backflow stabilisation −βρ/2 min(u·n, 0) u·w (0: none)",
                           Bounds::closed(0, 10)});
    p.outlets.push_back(std::move(outlet));
  }
  p.has_pressure_reference = root.has("pressure_reference");
  p.pressure_reference = root.get<std::vector<double>>(
      "pressure_reference", {},
      {"m", "point whose nearest vertex gets p = 0 (needed when no outflow exists)"});

  auto time = root.section("time", "time stepping");
  p.steady = time.get<bool>("steady", true, {"", "solve the steady equations"});
  if (!p.steady) {
    p.end_time = time.require<double>("end_time", {"s", "final time", Bounds::positive()});
    p.time_step = time.require<double>("step", {"s", "time step", Bounds::positive()});
  }

  auto benchmark = root.section("benchmark", "benchmark quantities written to summary.json");
  auto& b = p.benchmark;
  b.type = benchmark.choice(
      "type", "none", {"none", "cavity", "cylinder", "windkessel"},
      {"", "none | cavity (centreline profiles) | cylinder (forces) | windkessel (RCR check)"});
  if (b.type == "windkessel") {
    b.outlet = benchmark.require<std::string>("outlet", {"", "group of a windkessel outlet"});
    b.period = benchmark.require<double>(
        "period", {"s", "the statistics cover the last period", Bounds::positive()});
  }
  if (b.type == "cavity") {
    b.reference_y = benchmark.get<std::vector<double>>("reference_y", {}, {"m", "table y"});
    b.reference_u = benchmark.get<std::vector<double>>("reference_u", {}, {"m/s", "u(0.5, y)"});
    b.reference_x = benchmark.get<std::vector<double>>("reference_x", {}, {"m", "table x"});
    b.reference_v = benchmark.get<std::vector<double>>("reference_v", {}, {"m/s", "v(x, 0.5)"});
    if (b.reference_y.size() != b.reference_u.size())
      benchmark.fail("reference_u", "needs as many values as reference_y");
    if (b.reference_x.size() != b.reference_v.size())
      benchmark.fail("reference_v", "needs as many values as reference_x");
    b.profile_points = benchmark.get<int>(
        "profile_points", 129, {"", "points per centreline CSV", Bounds::closed(2, 1e5)});
  } else if (b.type == "cylinder") {
    b.body = benchmark.require<std::string>("body", {"", "boundary group of the body"});
    b.mean_velocity = benchmark.require<double>("mean_velocity",
                                                {"m/s", "Ū of c = 2F/(ρŪ²D)", Bounds::positive()});
    b.diameter =
        benchmark.require<double>("diameter", {"m", "D of c = 2F/(ρŪ²D)", Bounds::positive()});
    b.pressure_points = benchmark.get<std::vector<double>>(
        "pressure_points", {}, {"m", "x_A, y_A, x_B, y_B: Δp = p(A) − p(B)"});
    if (!b.pressure_points.empty() && b.pressure_points.size() != 4)
      benchmark.fail("pressure_points", "give 4 numbers: x_A, y_A, x_B, y_B (2D)");
    auto reference = benchmark.section("reference", "published values (relative errors)");
    b.reference_drag = reference.get<double>("drag_coefficient", 0.0, {"", "c_D (0: none)"});
    b.reference_lift = reference.get<double>("lift_coefficient", 0.0, {"", "c_L (0: none)"});
    b.reference_pressure_difference =
        reference.get<double>("pressure_difference", 0.0, {"Pa", "Δp (0: none)"});
  }
  p.write_vtk = root.section("output", "what the run writes")
                    .get<bool>("vtk", true, {"", "write velocity and pressure as VTK"});
  return p;
}

/// Values of component `component` of a vertex vector at `points` (n × dim, row-major), each
/// from the owned cell that contains it (NaN where none does). Collective.
std::vector<double> values_at(const mesh::Mesh& mesh, Vec vector, int n_components, int component,
                              const std::vector<double>& points) {
  const int dim = mesh.dim, k = dim + 1;
  const std::size_t n_points = points.size() / dim;
  std::vector<double> values(n_points, 0.0);
  std::vector<int> found(n_points, 0);
  fem::LocalValues local(vector);
  for (int c = 0; c < mesh.n_owned_cells; ++c) {
    const auto vertices = mesh.cell(c);
    double edges[3][3] = {}, g[4][3] = {};
    const double* x0 = mesh.point(vertices[0]).data();
    // Barycentric coordinates λ_a(x) = δ_a0 + ∇λ_a·(x − x0).
    if (dim == 2) {
      double e[2][2], g2[3][2];
      for (int a = 0; a < 2; ++a)
        for (int i = 0; i < 2; ++i) e[a][i] = mesh.point(vertices[a + 1])[i] - x0[i];
      fem::detail::gradients_from_edges<2>(e, g2);
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 2; ++i) g[a][i] = g2[a][i];
    } else {
      double e[3][3], g3[4][3];
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 3; ++i) e[a][i] = mesh.point(vertices[a + 1])[i] - x0[i];
      fem::detail::gradients_from_edges<3>(e, g3);
      for (int a = 0; a < 4; ++a)
        for (int i = 0; i < 3; ++i) g[a][i] = g3[a][i];
    }
    (void)edges;
    for (std::size_t q = 0; q < n_points; ++q) {
      if (found[q]) continue;
      double lambda[4], smallest = 1;
      for (int a = 0; a < k; ++a) {
        lambda[a] = a == 0 ? 1.0 : 0.0;
        for (int i = 0; i < dim; ++i) lambda[a] += g[a][i] * (points[q * dim + i] - x0[i]);
        smallest = std::min(smallest, lambda[a]);
      }
      if (smallest < -1e-10) continue;
      found[q] = 1;
      for (int a = 0; a < k; ++a)
        values[q] +=
            lambda[a] * local[static_cast<std::size_t>(vertices[a]) * n_components + component];
    }
  }
  // A point on a partition boundary is found on several ranks: the lowest rank's value counts.
  const int rank = rank_of(mesh.comm);
  std::vector<int> owner(n_points);
  for (std::size_t q = 0; q < n_points; ++q)
    owner[q] = found[q] ? rank : std::numeric_limits<int>::max();
  MPI_Allreduce(MPI_IN_PLACE, owner.data(), static_cast<int>(n_points), MPI_INT, MPI_MIN,
                mesh.comm);
  for (std::size_t q = 0; q < n_points; ++q)
    if (owner[q] != rank) values[q] = 0.0;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(n_points), MPI_DOUBLE, MPI_SUM,
                mesh.comm);
  for (std::size_t q = 0; q < n_points; ++q)
    if (owner[q] == std::numeric_limits<int>::max())
      values[q] = std::numeric_limits<double>::quiet_NaN();
  return values;
}

class FlowProblem final : public run::Problem {
 public:
  FlowProblem(const config::Section& root, MPI_Comm comm)
      : parameters_(read(root)),
        comm_(comm),
        mesh_(mesh::load_mesh(parameters_.mesh, comm, &quality_)) {
    const int dim = mesh_.dim;
    bool outflow = false;
    for (const auto& bc : parameters_.boundary) {
      const auto* group = mesh_.find_group(bc.group);
      if (!group || group->dim != dim - 1)
        throw InputError(fmt::format("{}: group: no boundary group '{}' in {} ({})", bc.where,
                                     bc.group, mesh_.source, boundary_group_names()));
      tags_.push_back(group->tag);
      if (bc.type == BoundaryCondition::Type::outflow) outflow = true;
      if (bc.type != BoundaryCondition::Type::velocity) continue;
      if (static_cast<int>(bc.value.size()) != dim)
        throw InputError(fmt::format("{}: value: needs {} components", bc.where, dim));
      if (bc.profile == BoundaryCondition::Profile::parabolic &&
          (static_cast<int>(bc.from.size()) != dim || static_cast<int>(bc.to.size()) != dim))
        throw InputError(fmt::format("{}: from/to: need {} coordinates each", bc.where, dim));
      if (bc.profile == BoundaryCondition::Profile::radial &&
          static_cast<int>(bc.centre.size()) != dim)
        throw InputError(fmt::format("{}: centre: needs {} coordinates", bc.where, dim));
    }
    for (const auto& outlet : parameters_.outlets) {
      const auto* group = mesh_.find_group(outlet.group);
      if (!group || group->dim != dim - 1)
        throw InputError(fmt::format("{}: group: no boundary group '{}' in {} ({})", outlet.where,
                                     outlet.group, mesh_.source, boundary_group_names()));
      for (std::size_t k = 0; k < parameters_.boundary.size(); ++k)
        if (tags_[k] == group->tag &&
            parameters_.boundary[k].type != BoundaryCondition::Type::outflow)
          throw InputError(fmt::format("{}: group: '{}' is also a velocity/no-slip boundary ({})",
                                       outlet.where, outlet.group, parameters_.boundary[k].where));
      outlet_tags_.push_back(group->tag);
      outflow = true;
    }
    if (!outflow && !parameters_.has_pressure_reference)
      throw InputError(fmt::format(
          "{}: no outflow boundary: give pressure_reference (a point) to fix the pressure level",
          mesh_.source));
    if (parameters_.has_pressure_reference &&
        static_cast<int>(parameters_.pressure_reference.size()) != dim)
      throw InputError(fmt::format("pressure_reference: needs {} coordinates", dim));
    const auto& b = parameters_.benchmark;
    if (b.type == "cylinder") {
      const auto* body = mesh_.find_group(b.body);
      if (!body || body->dim != dim - 1)
        throw InputError(fmt::format("benchmark.body: no boundary group '{}' in {} ({})", b.body,
                                     mesh_.source, boundary_group_names()));
      body_tag_ = body->tag;
    }
    if (b.type == "windkessel") {
      for (std::size_t k = 0; k < parameters_.outlets.size(); ++k)
        if (parameters_.outlets[k].group == b.outlet &&
            parameters_.outlets[k].type == OutletCondition::Type::windkessel)
          benchmark_outlet_ = static_cast<int>(k);
      if (benchmark_outlet_ < 0)
        throw InputError(fmt::format(
            "benchmark.outlet: '{}' is not a windkessel outlet of `outlets`", b.outlet));
      if (parameters_.steady)
        throw InputError("benchmark.type: windkessel needs a transient run (time.steady: false)");
    }
    if ((b.type == "cavity" || !b.pressure_points.empty()) && dim != 2)
      throw InputError("benchmark: the cavity profiles and pressure probes are 2D quantities");
  }

  void describe() const override {
    log::info("navier_stokes: {} on {}", parameters_.steady ? "steady" : "transient",
              parameters_.mesh.describe());
    log::info(
        "mesh: {} cells, {} vertices, dimension {}, {} rank(s); shape quality in [{:.3f}, "
        "{:.3f}]",
        mesh_.n_global_cells, mesh_.n_global_vertices, mesh_.dim, size_of(comm_),
        quality_.min_shape, quality_.max_shape);
    log::info("fluid: rho = {:g} kg/m^3, mu = {:g} Pa s, C_I = {:g}, {}", parameters_.fluid.density,
              parameters_.fluid.viscosity, parameters_.fluid.c_inverse,
              parameters_.fluid.convection ? "Navier-Stokes" : "Stokes");
  }

  void run(run::RunOutput& output) override {
    describe();
    NavierStokes fluid(mesh_, parameters_.fluid);
    log::info("linear solver: {}", fluid.describe_solver());
    setup_dirichlet(fluid);
    setup_outlets(fluid);
    const auto& p = parameters_;
    int newton_total = 0, linear_total = 0;
    TimeLevel level;
    if (p.steady) {
      write_boundary_values(fluid, std::numeric_limits<double>::infinity());
      set_outlet_pressures(fluid, 0.0);
      ScopedTimer timer(output.timers(), "solve");
      const auto report = fluid.solve(level, "steady solve");
      newton_total = report.iterations;
      linear_total = report.linear_iterations;
      log::info("steady: {} Newton iterations, {} linear iterations, residual {:.3e} -> {:.3e}",
                report.iterations, report.linear_iterations, report.residual_history.front(),
                report.residual_history.back());
      log::info("steady: Newton residuals {:.3e}", fmt::join(report.residual_history, ", "));
      record_step(fluid, level, output, 0.0, report);
    } else {
      auto previous = fem::create_vertex_vector(mesh_, mesh_.dim + 1);
      auto before = fem::create_vertex_vector(mesh_, mesh_.dim + 1);
      const int n_steps = static_cast<int>(std::ceil(p.end_time / p.time_step - 1e-9));
      Progress progress(n_steps, p.end_time);
      double time = 0, last_step = p.time_step;
      write_boundary_values(fluid, 0.0);
      for (int step = 1; step <= n_steps; ++step) {
        const double dt = std::min(p.time_step, p.end_time - time);
        COAPT_PETSC_CHECK(VecCopy(previous, before));
        COAPT_PETSC_CHECK(VecCopy(fluid.state(), previous));
        fem::update_ghosts(previous);
        fem::update_ghosts(before);
        level.time_step = dt;
        level.alpha = bdf_weights(step == 1 ? 1 : 2, dt / last_step);
        level.previous = previous;
        level.before_previous = before;
        time += dt;
        write_boundary_values(fluid, time);
        set_outlet_pressures(fluid, dt);
        NewtonReport report;
        {
          ScopedTimer timer(output.timers(), "solve");
          report = fluid.solve(level, fmt::format("step {} (t = {:g} s)", step, time));
        }
        if (step <= 2 || step == n_steps)
          log::info("step {}: Newton residuals {:.3e}", step,
                    fmt::join(report.residual_history, ", "));
        for (std::size_t k = 0; k < windkessels_.size(); ++k)
          if (windkessels_[k]) windkessels_[k]->advance(fluid.outlet_flow(k), dt);
        newton_total += report.iterations;
        linear_total += report.linear_iterations;
        last_step = dt;
        record_step(fluid, level, output, time, report);
        progress.step(
            step, time,
            fmt::format("newton {}, ksp {}", report.iterations, report.linear_iterations));
      }
    }
    for (std::size_t k = 0; k < windkessels_.size(); ++k)
      if (windkessels_[k])  // for a later restart: lumped::Windkessel::restore takes it back
        output.summary()["windkessel_state"][p.outlets[k].group] =
            io::Json::array_of(windkessels_[k]->state());
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = newton_total;
    iterations["linear"] = linear_total;
    {
      ScopedTimer timer(output.timers(), "benchmark");
      benchmark(fluid, level, output);
    }
    if (p.write_vtk) {
      ScopedTimer timer(output.timers(), "output");
      write_vtk(fluid, output, p.steady ? 0.0 : p.end_time);
    }
  }

 private:
  /// Velocity dofs of every velocity/no-slip group (later entries win at shared vertices) and
  /// the pinned pressure dof.
  void setup_dirichlet(NavierStokes& fluid) {
    const int dim = mesh_.dim, n = dim + 1;
    condition_of_vertex_.assign(static_cast<std::size_t>(mesh_.n_owned_vertices), -1);
    for (std::size_t k = 0; k < parameters_.boundary.size(); ++k) {
      if (parameters_.boundary[k].type == BoundaryCondition::Type::outflow) continue;
      for (int f = 0; f < mesh_.n_facets(); ++f) {
        if (mesh_.facet_tags[f] != tags_[k]) continue;
        for (int a = 0; a < dim; ++a) {
          const int v = mesh_.facets[static_cast<std::size_t>(f) * dim + a];
          if (v < mesh_.n_owned_vertices) condition_of_vertex_[v] = static_cast<int>(k);
        }
      }
    }
    std::vector<PetscInt> dofs;
    for (int v = 0; v < mesh_.n_owned_vertices; ++v)
      if (condition_of_vertex_[v] >= 0)
        for (int i = 0; i < dim; ++i) dofs.push_back(mesh_.global_vertex[v] * n + i);
    if (parameters_.has_pressure_reference) {
      // The vertex nearest to the point (lowest rank on a tie) gets p = 0.
      struct {
        double distance;
        int rank;
      } best{std::numeric_limits<double>::max(), rank_of(comm_)};
      int nearest = -1;
      for (int v = 0; v < mesh_.n_owned_vertices; ++v) {
        double d = 0;
        for (int i = 0; i < dim; ++i)
          d += std::pow(mesh_.point(v)[i] - parameters_.pressure_reference[i], 2);
        if (d < best.distance) {
          best.distance = d;
          nearest = v;
        }
      }
      const int rank = best.rank;
      MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm_);
      if (best.rank == rank && nearest >= 0) dofs.push_back(mesh_.global_vertex[nearest] * n + dim);
    }
    fluid.set_dirichlet_dofs(std::move(dofs));
  }

  /// Gives the fluid its outlets; builds a Windkessel per windkessel outlet. Collective.
  void setup_outlets(NavierStokes& fluid) {
    std::vector<Outlet> outlets;
    windkessels_.clear();
    for (std::size_t k = 0; k < parameters_.outlets.size(); ++k) {
      const auto& outlet = parameters_.outlets[k];
      outlets.push_back({outlet_tags_[k], outlet.backflow, 0.0, 0.0});
      windkessels_.push_back(outlet.type == OutletCondition::Type::windkessel
                                 ? std::make_unique<lumped::Windkessel>(outlet.windkessel)
                                 : nullptr);
      log::info(
          "outlet '{}': {}, backflow beta = {:g}", outlet.group,
          outlet.type == OutletCondition::Type::windkessel
              ? fmt::format("RCR R_p = {:g}, C = {:g}, R_d = {:g}, P_d = {:g}",
                            outlet.windkessel.proximal_resistance, outlet.windkessel.compliance,
                            outlet.windkessel.distal_resistance, outlet.windkessel.distal_pressure)
          : outlet.type == OutletCondition::Type::traction
              ? fmt::format("pressure {:g} Pa", outlet.pressure)
              : std::string("do-nothing"),
          outlet.backflow);
    }
    fluid.set_outlets(outlets);
  }

  /// P = R Q + offset of every outlet for a step of size dt (≤ 0: steady, where a Windkessel
  /// is its total resistance: P = (R_p + R_d) Q + P_d).
  void set_outlet_pressures(NavierStokes& fluid, double dt) {
    for (std::size_t k = 0; k < parameters_.outlets.size(); ++k) {
      const auto& outlet = parameters_.outlets[k];
      if (outlet.type == OutletCondition::Type::windkessel) {
        const auto& wk = outlet.windkessel;
        if (dt > 0) {
          const auto relation = windkessels_[k]->relation(dt);
          fluid.set_outlet_pressure(k, relation.effective_resistance, relation.offset);
        } else {
          fluid.set_outlet_pressure(k, wk.proximal_resistance + wk.distal_resistance,
                                    wk.distal_pressure);
        }
      } else {
        fluid.set_outlet_pressure(k, 0.0, outlet.pressure);
      }
    }
  }

  /// Series columns of the flows: flow_<group> (out of the domain) of each velocity group,
  /// outlet_flow_<group> and outlet_pressure_<group> of each outlet; keeps the benchmark's.
  void record_flows(NavierStokes& fluid, double time, io::CsvSeries& series) {
    for (std::size_t k = 0; k < parameters_.boundary.size(); ++k)
      if (parameters_.boundary[k].type == BoundaryCondition::Type::velocity)
        series.add("flow_" + parameters_.boundary[k].group, fluid.boundary_flow(tags_[k]));
    for (std::size_t k = 0; k < parameters_.outlets.size(); ++k) {
      const double flow = fluid.outlet_flow(k), pressure = fluid.outlet_pressure(k);
      series.add("outlet_flow_" + parameters_.outlets[k].group, flow);
      series.add("outlet_pressure_" + parameters_.outlets[k].group, pressure);
      if (static_cast<int>(k) == benchmark_outlet_) {
        history_time_.push_back(time);
        history_flow_.push_back(flow);
        history_pressure_.push_back(pressure);
      }
    }
  }

  /// Writes the boundary velocities at time `time` into the state (t = ∞: ramps finished).
  void write_boundary_values(NavierStokes& fluid, double time) {
    const int dim = mesh_.dim, n = dim + 1;
    for (int v = 0; v < mesh_.n_owned_vertices; ++v) {
      const int k = condition_of_vertex_[v];
      if (k < 0) continue;
      const auto& bc = parameters_.boundary[k];
      double factor = 0;
      if (bc.type == BoundaryCondition::Type::velocity) {
        factor = 1;
        if (bc.ramp_time > 0 && time < bc.ramp_time)
          factor = 0.5 * (1 - std::cos(std::numbers::pi * time / bc.ramp_time));
        if (bc.profile == BoundaryCondition::Profile::parabolic) {
          // s ∈ [0, 1] along from → to; the profile 4 s (1 − s) peaks at the midpoint.
          double along = 0, length2 = 0;
          for (int i = 0; i < dim; ++i) {
            along += (mesh_.point(v)[i] - bc.from[i]) * (bc.to[i] - bc.from[i]);
            length2 += std::pow(bc.to[i] - bc.from[i], 2);
          }
          const double s = std::clamp(along / length2, 0.0, 1.0);
          factor *= 4 * s * (1 - s);
        } else if (bc.profile == BoundaryCondition::Profile::radial) {
          double r2 = 0;
          for (int i = 0; i < dim; ++i) r2 += std::pow(mesh_.point(v)[i] - bc.centre[i], 2);
          factor *= std::max(0.0, 1 - r2 / (bc.radius * bc.radius));
        }
        factor *= waveform_factor(bc, time);
      }
      for (int i = 0; i < dim; ++i) {
        const double value =
            bc.type == BoundaryCondition::Type::velocity ? factor * bc.value[i] : 0;
        COAPT_PETSC_CHECK(
            VecSetValue(fluid.state(), mesh_.global_vertex[v] * n + i, value, INSERT_VALUES));
      }
    }
    COAPT_PETSC_CHECK(VecAssemblyBegin(fluid.state()));
    COAPT_PETSC_CHECK(VecAssemblyEnd(fluid.state()));
    fem::update_ghosts(fluid.state());
  }

  /// The waveform's factor at time t (1 when steady, t = ∞).
  static double waveform_factor(const BoundaryCondition& bc, double time) {
    if (!std::isfinite(time) || bc.waveform == BoundaryCondition::Waveform::none) return 1.0;
    if (bc.waveform == BoundaryCondition::Waveform::sinusoid)
      return 1 + bc.amplitude * std::sin(2 * std::numbers::pi * time / bc.period);
    double t = time;
    if (bc.period > 0) t = bc.times.front() + std::fmod(time - bc.times.front(), bc.period);
    if (t <= bc.times.front()) return bc.factors.front();
    if (t >= bc.times.back()) return bc.factors.back();
    const auto k = static_cast<std::size_t>(std::upper_bound(bc.times.begin(), bc.times.end(), t) -
                                            bc.times.begin());
    const double s = (t - bc.times[k - 1]) / (bc.times[k] - bc.times[k - 1]);
    return (1 - s) * bc.factors[k - 1] + s * bc.factors[k];
  }

  void record_step(NavierStokes& fluid, const TimeLevel& level, run::RunOutput& output, double time,
                   const NewtonReport& report) {
    auto& series = output.series();
    series.add("time", time);
    series.add("newton_iterations", report.iterations);
    series.add("linear_iterations", report.linear_iterations);
    series.add("residual", report.residual_history.back());
    if (body_tag_ >= 0) {
      const auto force = fluid.boundary_force(body_tag_, level);
      const auto& b = parameters_.benchmark;
      const double scale =
          2.0 / (parameters_.fluid.density * b.mean_velocity * b.mean_velocity * b.diameter);
      series.add("drag_coefficient", scale * force[0]);
      series.add("lift_coefficient", scale * force[1]);
    }
    record_flows(fluid, time, series);
    series.end_row();
  }

  void benchmark(NavierStokes& fluid, const TimeLevel& level, run::RunOutput& output) {
    const auto& b = parameters_.benchmark;
    auto& json = output.summary()["benchmark"];
    json["cells"] = static_cast<std::int64_t>(mesh_.n_global_cells);
    json["vertices"] = static_cast<std::int64_t>(mesh_.n_global_vertices);
    const int n = mesh_.dim + 1;
    if (b.type == "cylinder") {
      const auto force = fluid.boundary_force(body_tag_, level);
      const double scale =
          2.0 / (parameters_.fluid.density * b.mean_velocity * b.mean_velocity * b.diameter);
      const double drag = scale * force[0], lift = scale * force[1];
      json["drag_force"] = force[0];
      json["lift_force"] = force[1];
      json["drag_coefficient"] = drag;
      json["lift_coefficient"] = lift;
      log::info("c_D = {:.8f}, c_L = {:.8f}", drag, lift);
      if (b.reference_drag != 0) json["drag_error"] = std::abs(drag / b.reference_drag - 1);
      if (b.reference_lift != 0) json["lift_error"] = std::abs(lift / b.reference_lift - 1);
      if (!b.pressure_points.empty()) {
        const auto p = values_at(mesh_, fluid.state(), n, mesh_.dim, b.pressure_points);
        const double difference = p[0] - p[1];
        json["pressure_difference"] = difference;
        log::info("Delta p = {:.8f} Pa", difference);
        if (b.reference_pressure_difference != 0)
          json["pressure_difference_error"] =
              std::abs(difference / b.reference_pressure_difference - 1);
      }
    } else if (b.type == "cavity") {
      cavity_profiles(fluid, output, json);
    } else if (b.type == "windkessel") {
      windkessel_benchmark(json);
    }
  }

  /// Checks the outlet's (Q, P) history against the RCR model integrated independently:
  /// C dP_c/dt = Q(t) − (P_c − P_d)/R_d with Q linear between the steps (constant Q₁ on the
  /// first step: the initial state is not a solution), 64 RK4 substeps per step, and
  /// P_RCR = R_p Q + P_c. Reports max over the last period of |P − P_RCR| / max|P|, and the
  /// mean (trapezoidal) and amplitude ((max − min)/2) of P over the last period.
  void windkessel_benchmark(io::Json& json) {
    const auto& b = parameters_.benchmark;
    const auto& wk = parameters_.outlets[static_cast<std::size_t>(benchmark_outlet_)].windkessel;
    const auto& t = history_time_;
    const auto& q = history_flow_;
    const auto& p = history_pressure_;
    if (t.size() < 2) return;
    const auto rate = [&](double flow, double pc) {
      return (flow - (pc - wk.distal_pressure) / wk.distal_resistance) / wk.compliance;
    };
    std::vector<double> model(t.size());
    double pc = wk.initial_pressure, previous_time = 0;
    constexpr int substeps = 64;
    for (std::size_t k = 0; k < t.size(); ++k) {
      const double dt = t[k] - previous_time;
      const double q0 = k == 0 ? q[0] : q[k - 1], q1 = q[k];
      const double h = dt / substeps;
      for (int j = 0; j < substeps; ++j) {
        const auto flow = [&](double s) { return q0 + (q1 - q0) * s; };
        const double s0 = static_cast<double>(j) / substeps, s1 = (j + 1.0) / substeps;
        const double sm = 0.5 * (s0 + s1);
        const double k1 = rate(flow(s0), pc), k2 = rate(flow(sm), pc + 0.5 * h * k1),
                     k3 = rate(flow(sm), pc + 0.5 * h * k2), k4 = rate(flow(s1), pc + h * k3);
        pc += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      }
      model[k] = wk.proximal_resistance * q1 + pc;
      previous_time = t[k];
    }
    const double start = t.back() - b.period * (1 + 1e-9);
    double max_pressure = 0, max_difference = 0, low = std::numeric_limits<double>::max(),
           high = -low, integral = 0, flow_integral = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
      if (t[k] < start) continue;
      max_pressure = std::max(max_pressure, std::abs(p[k]));
      max_difference = std::max(max_difference, std::abs(p[k] - model[k]));
      low = std::min(low, p[k]);
      high = std::max(high, p[k]);
      if (k > 0 && t[k - 1] >= start) {
        integral += 0.5 * (p[k] + p[k - 1]) * (t[k] - t[k - 1]);
        flow_integral += 0.5 * (q[k] + q[k - 1]) * (t[k] - t[k - 1]);
      }
    }
    const double covered =
        t.back() - *std::find_if(t.begin(), t.end(), [&](double x) { return x >= start; });
    json["rcr_relative_error"] = max_difference / max_pressure;
    json["outlet_pressure_mean"] = covered > 0 ? integral / covered : p.back();
    json["outlet_pressure_amplitude"] = 0.5 * (high - low);
    json["outlet_flow_mean"] = covered > 0 ? flow_integral / covered : q.back();
    json["last_period_start"] = t.back() - covered;
    log::info(
        "windkessel '{}': max |P - P_RCR| / max |P| = {:.3e} over the last period; P mean "
        "{:.6g} Pa, amplitude {:.6g} Pa",
        b.outlet, max_difference / max_pressure, integral / std::max(covered, 1e-300),
        0.5 * (high - low));
  }

  void cavity_profiles(NavierStokes& fluid, run::RunOutput& output, io::Json& json) {
    const auto& b = parameters_.benchmark;
    const int n = mesh_.dim + 1;
    const int m = b.profile_points;
    // u(0.5, y) and v(x, 0.5) at m uniform points and at the table's points.
    std::vector<double> line_u, line_v, table_u, table_v;
    for (int k = 0; k < m; ++k) {
      const double s = static_cast<double>(k) / (m - 1);
      line_u.insert(line_u.end(), {0.5, s});
      line_v.insert(line_v.end(), {s, 0.5});
    }
    for (double y : b.reference_y) table_u.insert(table_u.end(), {0.5, y});
    for (double x : b.reference_x) table_v.insert(table_v.end(), {x, 0.5});
    const auto u = values_at(mesh_, fluid.state(), n, 0, line_u);
    const auto v = values_at(mesh_, fluid.state(), n, 1, line_v);
    const auto u_table = values_at(mesh_, fluid.state(), n, 0, table_u);
    const auto v_table = values_at(mesh_, fluid.state(), n, 1, table_v);
    double error_u = 0, error_v = 0;
    for (std::size_t k = 0; k < u_table.size(); ++k)
      error_u = std::max(error_u, std::abs(u_table[k] - b.reference_u[k]));
    for (std::size_t k = 0; k < v_table.size(); ++k)
      error_v = std::max(error_v, std::abs(v_table[k] - b.reference_v[k]));
    if (!b.reference_u.empty()) json["max_error_u"] = error_u;
    if (!b.reference_v.empty()) json["max_error_v"] = error_v;
    log::info("centrelines: max |u - u_ref| = {:.4e}, max |v - v_ref| = {:.4e}", error_u, error_v);
    if (rank_of(comm_) != 0) return;
    const auto write = [&](const std::string& name, const std::string& header,
                           const std::vector<double>& points, int coordinate,
                           const std::vector<double>& values,
                           const std::vector<double>* reference) {
      std::ofstream file(output.directory() / name);
      if (!file) throw Error(fmt::format("cannot write {}", (output.directory() / name).string()));
      file << header << "\n";
      for (std::size_t k = 0; k < values.size(); ++k) {
        file << fmt::format("{:.17g},{:.17g}", points[2 * k + coordinate], values[k]);
        if (reference) file << fmt::format(",{:.17g}", (*reference)[k]);
        file << "\n";
      }
    };
    write("centreline_u.csv", "y,u", line_u, 1, u, nullptr);
    write("centreline_v.csv", "x,v", line_v, 0, v, nullptr);
    write("reference_u.csv", "y,u,u_reference", table_u, 1, u_table, &b.reference_u);
    write("reference_v.csv", "x,v,v_reference", table_v, 0, v_table, &b.reference_v);
  }

  void write_vtk(NavierStokes& fluid, run::RunOutput& output, double time) {
    const int dim = mesh_.dim, n = dim + 1;
    fem::LocalValues state(fluid.state());
    std::vector<double> velocity(static_cast<std::size_t>(mesh_.n_vertices()) * dim),
        pressure(static_cast<std::size_t>(mesh_.n_vertices()));
    for (int v = 0; v < mesh_.n_vertices(); ++v) {
      for (int i = 0; i < dim; ++i)
        velocity[static_cast<std::size_t>(v) * dim + i] =
            state[static_cast<std::size_t>(v) * n + i];
      pressure[v] = state[static_cast<std::size_t>(v) * n + dim];
    }
    const std::vector<io::Field> fields = {
        {"velocity", dim, io::Field::Location::vertex, velocity},
        {"pressure", 1, io::Field::Location::vertex, pressure},
    };
    output.vtk("solution").write(mesh_, time, fields);
  }

  std::string boundary_group_names() const {
    std::string names;
    for (const auto& group : mesh_.groups)
      if (group.dim == mesh_.dim - 1) names += (names.empty() ? "" : ", ") + group.name;
    return names.empty() ? "it has none" : "it has: " + names;
  }

  const Parameters parameters_;
  MPI_Comm comm_;
  mesh::QualityReport quality_;
  mesh::Mesh mesh_;
  std::vector<int> tags_;                 ///< facet tag of each boundary entry
  std::vector<int> condition_of_vertex_;  ///< per owned vertex: the boundary entry, or −1
  int body_tag_ = -1;
  std::vector<int> outlet_tags_;  ///< facet tag of each outlet entry
  std::vector<std::unique_ptr<lumped::Windkessel>> windkessels_;  ///< per outlet, or null
  int benchmark_outlet_ = -1;  ///< the outlet of the windkessel benchmark
  std::vector<double> history_time_, history_flow_, history_pressure_;  ///< of that outlet
};

}  // namespace

std::unique_ptr<run::Problem> create_flow_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<FlowProblem>(root, comm);
}

}  // namespace coapt::fluid
