#include "coapt/fluid/fluid_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/line_search.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fluid/kernels.hpp"

namespace coapt::fluid {
namespace {

using config::Bounds;

}  // namespace

double TimeWaveform::factor(double time) const {
  if (!std::isfinite(time) || kind == Kind::none) return 1.0;
  if (kind == Kind::sinusoid) return 1 + amplitude * std::sin(2 * std::numbers::pi * time / period);
  double t = time;
  if (period > 0) t = times.front() + std::fmod(time - times.front(), period);
  if (t <= times.front()) return factors.front();
  if (t >= times.back()) return factors.back();
  const auto k =
      static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double s = (t - times[k - 1]) / (times[k] - times[k - 1]);
  return (1 - s) * factors[k - 1] + s * factors[k];
}

void TimeWaveform::parse_csv(const std::string& text, const std::string& name,
                             std::vector<double>& times, std::vector<double>& factors) {
  times.clear();
  factors.clear();
  std::istringstream lines(text);
  std::string line;
  bool header_allowed = true;
  for (int number = 1; std::getline(lines, line); ++number) {
    const auto comment = line.find('#');
    if (comment != std::string::npos) line.erase(comment);
    const std::string row = line;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    double time = 0, factor = 0;
    std::string rest;
    const bool numbers = static_cast<bool>(fields >> time >> factor);
    if (numbers && !(fields >> rest) && std::isfinite(time) && std::isfinite(factor)) {
      if (!times.empty() && !(time > times.back()))
        throw InputError(
            fmt::format("{}:{}: time {:g} s does not increase (the row before: {:g} s)", name,
                        number, time, times.back()));
      times.push_back(time);
      factors.push_back(factor);
      header_allowed = false;
      continue;
    }
    double first = 0;
    std::istringstream probe(line);
    if (header_allowed && !(probe >> first)) {  // a header line such as "time,factor"
      header_allowed = false;
      continue;
    }
    throw InputError(
        fmt::format("{}:{}: expected two numbers 'time, factor', got '{}'", name, number, row));
  }
  if (times.size() < 2)
    throw InputError(
        fmt::format("{}: needs at least 2 rows 'time, factor', has {}", name, times.size()));
}

TimeWaveform TimeWaveform::read(const config::Section& waveform) {
  TimeWaveform w;
  const auto kind = waveform.choice(
      "type", "none", {"none", "sinusoid", "table", "csv"},
      {"",
       "none | sinusoid (1 + a sin(2πt/T)) | table (linear in time; steady runs: none) | csv "
       "(the table read from a file)"});
  if (kind == "sinusoid") {
    w.kind = Kind::sinusoid;
    w.amplitude = waveform.require<double>("amplitude", {"", "a of 1 + a sin(2πt/T)"});
    w.period = waveform.require<double>("period", {"s", "period T", Bounds::positive()});
  } else if (kind == "table" || kind == "csv") {
    w.kind = Kind::table;
    if (kind == "table") {
      w.times = waveform.require<std::vector<double>>("times", {"s", "table times, increasing"});
      w.factors = waveform.require<std::vector<double>>("values", {"", "factor at each time"});
      if (w.times.size() < 2 || w.times.size() != w.factors.size())
        waveform.fail("values", "needs at least 2 entries, as many as times");
      for (std::size_t k = 1; k < w.times.size(); ++k)
        if (!(w.times[k] > w.times[k - 1])) waveform.fail("times", "must increase");
    } else {
      const auto file = waveform.require<std::string>(
          "file", {"", "csv: rows 'time [s], factor', increasing times (relative to the case)"});
      const std::filesystem::path path =
          std::filesystem::path(file).is_absolute()
              ? std::filesystem::path(file)
              : (std::filesystem::path(waveform.case_directory()) / file).lexically_normal();
      std::ifstream in(path);
      if (!in)
        waveform.fail("file", fmt::format("cannot read the waveform file {}", path.string()));
      std::ostringstream text;
      text << in.rdbuf();
      parse_csv(text.str(), path.string(), w.times, w.factors);
    }
    w.period =
        waveform.get<double>("period", 0.0,
                             {"s", "repeat the table with this period (0: hold the last value)",
                              Bounds::non_negative()});
  }
  return w;
}

FluidCase FluidCase::read(const config::Section& section, const config::Section& properties) {
  FluidCase p;
  p.mesh = mesh::MeshInput::read(section.section("mesh", "the mesh"), section.case_directory());
  const auto& fluid = properties;
  p.fluid.density = fluid.get<double>("density", 1.0, {"kg/m^3", "density ρ", Bounds::positive()});
  p.fluid.viscosity =
      fluid.get<double>("viscosity", 1e-3, {"Pa s", "dynamic viscosity μ", Bounds::positive()});
  p.fluid.convection = fluid.get<bool>("convection", true, {"", "false: Stokes flow (no u·∇u)"});
  const std::string viscous_form = fluid.choice(
      "viscous_form", "laplace", {"laplace", "stress"},
      {"",
       "laplace: μ∇w:∇u, natural condition μ∂ₙu − pn = 0 (the DFG do-nothing) | stress: "
       "2μ∇w:ε(u), natural condition σn = 0"});
  p.fluid.viscous_form = viscous_form == "stress" ? ViscousForm::stress : ViscousForm::laplace;
  p.fluid.c_inverse =
      fluid.get<double>("c_inverse", kDefaultCInverse,
                        {"", "C_I of the stabilisation parameter τ_M (9: nodally exact 1D limits)",
                         Bounds::positive()});
  p.fluid.tau_time_term = fluid.get<bool>(
      "tau_time_term", true,
      {"",
       "include (2/Δt)² in τ_M (transient runs); false: τ_M from the convective and viscous "
       "terms only, so that the stabilisation does not fade as Δt → 0 (time-step studies, "
       "very small steps)"});
  p.fluid.covered_continuity_factor = fluid.get<double>(
      "covered_continuity_factor", 1.0,
      {"",
       "factor on the continuity equation (its Galerkin and PSPG parts) in the cells whose "
       "vertices all carry an immersed solid's velocity constraint (or a wall's velocity "
       "condition, one at least the solid's), where the fluid is fictitious: below 1 it "
       "narrows the PSPG flux through a closed valve's leaflets (docs/verification/fsci.md); "
       "1: the same equation everywhere",
       Bounds{0.0, 1.0, true, false}});
  p.fluid.covered_continuity_coverage = fluid.get<double>(
      "covered_continuity_coverage", p.fluid.covered_continuity_coverage,
      {"",
       "covered_continuity_factor applies only to the cells of which the solids cover at "
       "least this fraction: a cell partly outside them (one spanning the gap between two "
       "leaflets as they close) holds real fluid and keeps its whole continuity equation, so "
       "that the fluid's mass balance stays exact there; 0: the vertex rule alone",
       Bounds::closed(0.0, 1.0)});
  auto newton = fluid.section("newton", "Newton's method per step");
  p.fluid.newton_relative_tolerance = newton.get<double>(
      "relative_tolerance", 1e-8, {"", "stop when ‖R‖ ≤ rtol ‖R₀‖", Bounds::open(0, 1)});
  p.fluid.newton_absolute_tolerance = newton.get<double>(
      "absolute_tolerance", 1e-10, {"", "or when ‖R‖ ≤ atol", Bounds::non_negative()});
  p.fluid.newton_max_iterations =
      newton.get<int>("max_iterations", 25, {"", "Newton iterations", Bounds::closed(1, 1000)});
  p.fluid.newton_line_search = fem::read_line_search(newton);
  p.fluid.reuse_preconditioner = newton.get<int>(
      "reuse_preconditioner", 10,
      {"",
       "a time step's preconditioner serves its later Newton and coupling iterations: the LU "
       "factorisation (the 2D default, or -fluid_pc_type lu) until a GMRES solve on it needs "
       "more than this many iterations, in a time step the fieldsplit (the 3D default) until a "
       "solve needs this many more than the last one on a new fieldsplit; then it is built "
       "afresh. 0: built at every Newton iteration",
       Bounds::closed(0, 100)});

  for (const auto& entry : section.sections("boundary", "boundary conditions, in order")) {
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
      const auto profile =
          entry.choice("profile", "constant", {"constant", "parabolic", "rectangle", "radial"},
                       {"",
                        "constant | parabolic (between `from` and `to`) | rectangle (over the box "
                        "`from`–`to`) | radial (about `centre`)"});
      if (profile == "parabolic" || profile == "rectangle") {
        bc.profile = profile == "parabolic" ? BoundaryCondition::Profile::parabolic
                                            : BoundaryCondition::Profile::rectangle;
        bc.from = entry.require<std::vector<double>>(
            "from", {"m", "one end of the profile (rectangle: a corner of the inlet)"});
        bc.to = entry.require<std::vector<double>>("to", {"m", "the other end (opposite corner)"});
      } else if (profile == "radial") {
        bc.profile = BoundaryCondition::Profile::radial;
        bc.centre = entry.require<std::vector<double>>(
            "centre", {"m", "radial: centre of the inlet (value × (1 − r²/radius²))"});
        bc.radius = entry.require<double>("radius",
                                          {"m", "radial: radius of the inlet", Bounds::positive()});
      }
      bc.waveform =
          TimeWaveform::read(entry.section("waveform", "periodic factor on the value in time"));
      bc.ramp_time = entry.get<double>(
          "ramp_time", 0.0,
          {"s", "smooth ramp (1 − cos(πt/T))/2 up to this time (0: none)", Bounds::non_negative()});
    }
    p.boundary.push_back(std::move(bc));
  }
  if (p.boundary.empty()) section.fail("boundary", "the case needs boundary conditions");
  for (const auto& entry : section.sections("outlets", "outlet pressures (traction −P n)")) {
    OutletCondition outlet;
    outlet.where = entry.where();
    outlet.group = entry.require<std::string>("group", {"", "boundary group of the outlet"});
    const auto type = entry.choice(
        "type", "do_nothing", {"do_nothing", "traction", "windkessel"},
        {"", "do_nothing (P = 0) | traction (fixed P) | windkessel (RCR, coupled implicitly)"});
    outlet.type = type == "do_nothing" ? OutletCondition::Type::do_nothing
                  : type == "traction" ? OutletCondition::Type::traction
                                       : OutletCondition::Type::windkessel;
    if (outlet.type == OutletCondition::Type::traction) {
      outlet.pressure = entry.require<double>(
          "pressure", {"Pa", "traction: outlet pressure P (times the waveform's factor)"});
      outlet.waveform = TimeWaveform::read(entry.section(
          "waveform", "traction: factor on the pressure in time (a pressure-driven inlet)"));
    }
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
  p.has_pressure_reference = section.has("pressure_reference");
  p.pressure_reference = section.get<std::vector<double>>(
      "pressure_reference", {},
      {"m", "point whose nearest vertex gets p = 0 (needed when no outflow exists)"});

  return p;
}

TimeSettings TimeSettings::read(const config::Section& root) {
  TimeSettings t;
  auto time = root.section("time", "time stepping");
  t.steady = time.get<bool>("steady", true, {"", "solve the steady equations"});
  if (!t.steady) {
    t.end_time = time.require<double>("end_time", {"s", "final time", Bounds::positive()});
    t.time_step = time.require<double>("step", {"s", "time step", Bounds::positive()});
  }

  return t;
}

int TimeSettings::n_steps() const {
  return steady ? 0 : static_cast<int>(std::ceil(end_time / time_step - 1e-9));
}

double TimeSettings::step_from(double time) const {
  const double left = end_time - time;
  return left < time_step * (1 - 1e-9) ? left : time_step;
}

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

FluidModel::FluidModel(FluidCase parameters, MPI_Comm comm, int level_offset)
    : parameters_([&] {
        mesh::add_refinement_levels(parameters.mesh, level_offset, "mesh.level");
        return std::move(parameters);
      }()),
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
    if ((bc.profile == BoundaryCondition::Profile::parabolic ||
         bc.profile == BoundaryCondition::Profile::rectangle) &&
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
}

FluidModel::~FluidModel() = default;

void FluidModel::describe(const std::string& title) const {
  log::info("{} on {}", title, parameters_.mesh.describe());
  log::info(
      "mesh: {} cells, {} vertices, dimension {}, {} rank(s); shape quality in [{:.3f}, "
      "{:.3f}]",
      mesh_.n_global_cells, mesh_.n_global_vertices, mesh_.dim, size_of(comm_), quality_.min_shape,
      quality_.max_shape);
  log::info(
      "fluid: rho = {:g} kg/m^3, mu = {:g} Pa s, C_I = {:g}{}{}, {}, {} form of the viscous term",
      parameters_.fluid.density, parameters_.fluid.viscosity, parameters_.fluid.c_inverse,
      parameters_.fluid.tau_time_term ? "" : " (tau_M without the time term)",
      parameters_.fluid.covered_continuity_factor == 1.0
          ? std::string()
          : fmt::format(", continuity x {:g} in the cells the solids cover ({:g} of the cell)",
                        parameters_.fluid.covered_continuity_factor,
                        parameters_.fluid.covered_continuity_coverage),
      parameters_.fluid.convection ? "Navier-Stokes" : "Stokes",
      parameters_.fluid.viscous_form == ViscousForm::stress ? "stress" : "Laplace");
}

int FluidModel::boundary_tag(const std::string& name, const std::string& key) const {
  const auto* group = mesh_.find_group(name);
  if (!group || group->dim != mesh_.dim - 1)
    throw InputError(fmt::format("{}: no boundary group '{}' in {} ({})", key, name, mesh_.source,
                                 boundary_group_names()));
  return group->tag;
}

void FluidModel::start(double time) {
  fluid_ = std::make_unique<NavierStokes>(mesh_, parameters_.fluid);
  log::info("linear solver: {}", fluid_->describe_solver());
  setup_dirichlet();
  setup_outlets();
  previous_ = fem::create_vertex_vector(mesh_, mesh_.dim + 1);
  before_ = fem::create_vertex_vector(mesh_, mesh_.dim + 1);
  oldest_ = fem::create_vertex_vector(mesh_, mesh_.dim + 1);
  committed_level_valid_ = false;
  time_ = committed_time_ = time;
  steps_ = 0;
  level_ = TimeLevel{};
  write_boundary_values(time);
  COAPT_PETSC_CHECK(VecCopy(fluid_->state(), previous_));
  fem::update_ghosts(previous_);
}

NewtonReport FluidModel::solve_steady(const std::string& label) {
  level_ = TimeLevel{};
  write_boundary_values(std::numeric_limits<double>::infinity());
  set_outlet_pressures(0.0);
  fluid_->refresh_preconditioner();
  return fluid_->solve(level_, label);
}

void FluidModel::begin_step(double dt) {
  fluid_->refresh_preconditioner();
  level_.time_step = dt;
  level_.alpha = bdf_weights(steps_ == 0 ? 1 : 2, dt / (steps_ == 0 ? dt : last_step_));
  level_.previous = previous_;
  level_.before_previous = before_;
  committed_level_valid_ = false;
  time_ = committed_time_ + dt;
  write_boundary_values(time_);
  set_outlet_pressures(dt);
}

NewtonReport FluidModel::solve(const std::string& label) {
  return fluid_->solve(level_, label);
}

void FluidModel::commit_step() {
  const double dt = level_.time_step;
  for (std::size_t k = 0; k < windkessels_.size(); ++k)
    if (windkessels_[k]) windkessels_[k]->advance(fluid_->outlet_flow(k), dt);
  COAPT_PETSC_CHECK(VecCopy(before_, oldest_));
  COAPT_PETSC_CHECK(VecCopy(previous_, before_));
  COAPT_PETSC_CHECK(VecCopy(fluid_->state(), previous_));
  fem::update_ghosts(previous_);
  fem::update_ghosts(before_);
  fem::update_ghosts(oldest_);
  committed_level_ = level_;
  committed_level_.previous = before_;
  committed_level_.before_previous = oldest_;
  committed_level_valid_ = true;
  committed_time_ = time_;
  last_step_ = dt;
  ++steps_;
}

void FluidModel::restore_step() {
  COAPT_PETSC_CHECK(VecCopy(previous_, fluid_->state()));
  fem::update_ghosts(fluid_->state());
  time_ = committed_time_;
  // the committed step's history is untouched by the dropped trial
  committed_level_valid_ = steps_ > 0 && committed_level_.time_step > 0;
}

void FluidModel::write_checkpoint(run::CheckpointWriter& writer) const {
  const int n = mesh_.dim + 1;
  writer.add_vertex_field("fluid_u", mesh_, previous_, n);
  writer.add_vertex_field("fluid_u_before", mesh_, before_, n);
  auto& state = writer.state()["fluid"];
  state["steps"] = steps_;
  state["time"] = committed_time_;
  state["last_step"] = last_step_;
  auto& windkessels = state["windkessels"] = io::Json::object();
  for (std::size_t k = 0; k < windkessels_.size(); ++k)
    if (windkessels_[k])
      windkessels[parameters_.outlets[k].group] = io::Json::array_of(windkessels_[k]->state());
}

void FluidModel::read_checkpoint(const run::CheckpointReader& reader) {
  const auto folder = reader.directory().string();
  const auto& checkpoint = reader.state();
  if (!checkpoint.contains("fluid") || !checkpoint.at("fluid").is_object())
    throw InputError(fmt::format("{}: the checkpoint holds no fluid state", folder));
  const auto& state = checkpoint.at("fluid");
  const int n = mesh_.dim + 1;
  reader.read_vertex_field("fluid_u", mesh_, previous_, n);
  reader.read_vertex_field("fluid_u_before", mesh_, before_, n);
  COAPT_PETSC_CHECK(VecCopy(previous_, fluid_->state()));
  fem::update_ghosts(fluid_->state());
  steps_ = static_cast<int>(state.at("steps").as_int());
  time_ = committed_time_ = state.at("time").as_double();
  last_step_ = state.at("last_step").as_double();
  const auto& windkessels = state.at("windkessels");
  std::size_t restored = 0;
  for (std::size_t k = 0; k < windkessels_.size(); ++k) {
    if (!windkessels_[k]) continue;
    const auto& group = parameters_.outlets[k].group;
    if (!windkessels.contains(group))
      throw InputError(
          fmt::format("{}: the checkpoint has no Windkessel state for outlet '{}'", folder, group));
    std::vector<double> values;
    for (const auto& value : windkessels.at(group).as_array()) values.push_back(value.as_double());
    try {
      windkessels_[k]->restore(values);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: outlet '{}': {}", folder, group, e.what()));
    }
    ++restored;
  }
  if (restored != windkessels.size())
    throw InputError(fmt::format(
        "{}: the checkpoint has {} Windkessel state(s), the case {} Windkessel outlet(s)", folder,
        windkessels.size(), restored));
}

void FluidModel::set_velocity_constraint(std::span<const int> vertices,
                                         std::span<const double> velocities,
                                         std::span<const double> cell_coverage) {
  fluid_->set_velocity_constraint(vertices, velocities, cell_coverage);
}

std::vector<double> FluidModel::constraint_reactions() {
  return fluid_->constraint_reactions(level_);
}

void FluidModel::set_velocity_penalty(std::span<const int> vertices,
                                      std::span<const double> weights,
                                      std::span<const double> targets, double time_scale) {
  fluid_->set_velocity_penalty(vertices, weights, targets, time_scale);
}

std::vector<double> FluidModel::penalty_reactions() {
  return fluid_->penalty_reactions(level_);
}

std::vector<double> FluidModel::boundary_force(int tag) {
  return fluid_->boundary_force(tag, force_level());
}

void FluidModel::record_flows(io::CsvSeries& series) const {
  for (std::size_t k = 0; k < parameters_.boundary.size(); ++k)
    if (parameters_.boundary[k].type == BoundaryCondition::Type::velocity)
      series.add("flow_" + parameters_.boundary[k].group, fluid_->boundary_flow(tags_[k]));
  for (std::size_t k = 0; k < parameters_.outlets.size(); ++k) {
    series.add("outlet_flow_" + parameters_.outlets[k].group, fluid_->outlet_flow(k));
    series.add("outlet_pressure_" + parameters_.outlets[k].group, fluid_->outlet_pressure(k));
  }
}

void FluidModel::write_windkessel_states(run::RunOutput& output) const {
  for (std::size_t k = 0; k < windkessels_.size(); ++k)
    if (windkessels_[k])  // for a later restart: lumped::Windkessel::restore takes it back
      output.summary()["windkessel_state"][parameters_.outlets[k].group] =
          io::Json::array_of(windkessels_[k]->state());
}

double FluidModel::kinetic_energy() const {
  const int dim = mesh_.dim, n = dim + 1;
  fem::LocalValues state(fluid_->state());
  double energy = 0;
  for (int c = 0; c < mesh_.n_owned_cells; ++c) {
    const double share = std::abs(mesh::cell_signed_measure(mesh_, c)) / (dim + 1);
    for (const int v : mesh_.cell(c))
      for (int i = 0; i < dim; ++i)
        energy += share * std::pow(state[static_cast<std::size_t>(v) * n + i], 2);
  }
  MPI_Allreduce(MPI_IN_PLACE, &energy, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return 0.5 * parameters_.fluid.density * energy;
}

std::vector<char> FluidModel::velocity_condition_vertices() const {
  if (condition_of_vertex_.size() != static_cast<std::size_t>(mesh_.n_owned_vertices))
    throw InternalError("FluidModel::velocity_condition_vertices before start()");
  std::vector<char> fixed(condition_of_vertex_.size(), 0);
  for (std::size_t v = 0; v < fixed.size(); ++v) fixed[v] = condition_of_vertex_[v] >= 0 ? 1 : 0;
  return fixed;
}

void FluidModel::setup_dirichlet() {
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
  fluid_->set_dirichlet_dofs(std::move(dofs));
}

/// Gives the fluid its outlets; builds a Windkessel per windkessel outlet. Collective.
void FluidModel::setup_outlets() {
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
  fluid_->set_outlets(outlets);
}

/// P = R Q + offset of every outlet for a step of size dt (≤ 0: steady, where a Windkessel
/// is its total resistance: P = (R_p + R_d) Q + P_d).
void FluidModel::set_outlet_pressures(double dt) {
  for (std::size_t k = 0; k < parameters_.outlets.size(); ++k) {
    const auto& outlet = parameters_.outlets[k];
    if (outlet.type == OutletCondition::Type::windkessel) {
      const auto& wk = outlet.windkessel;
      if (dt > 0) {
        const auto relation = windkessels_[k]->relation(dt);
        fluid_->set_outlet_pressure(k, relation.effective_resistance, relation.offset);
      } else {
        fluid_->set_outlet_pressure(k, wk.proximal_resistance + wk.distal_resistance,
                                    wk.distal_pressure);
      }
    } else {  // steady solves (dt = 0) take the waveform's factor 1
      const double time = dt > 0 ? time_ : std::numeric_limits<double>::infinity();
      fluid_->set_outlet_pressure(k, 0.0, outlet.pressure * outlet.waveform.factor(time));
    }
  }
}

/// Writes the boundary velocities at time `time` into the state (t = ∞: ramps finished).
void FluidModel::write_boundary_values(double time) {
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
      } else if (bc.profile == BoundaryCondition::Profile::rectangle) {
        // Per coordinate i in which the box has extent, s_i ∈ [0, 1] from from_i to to_i: the
        // product Π 4 s_i (1 − s_i) peaks at the centre of the inlet and vanishes on its edges.
        for (int i = 0; i < dim; ++i) {
          const double extent = bc.to[i] - bc.from[i];
          if (extent == 0) continue;
          const double s = std::clamp((mesh_.point(v)[i] - bc.from[i]) / extent, 0.0, 1.0);
          factor *= 4 * s * (1 - s);
        }
      } else if (bc.profile == BoundaryCondition::Profile::radial) {
        double r2 = 0;
        for (int i = 0; i < dim; ++i) r2 += std::pow(mesh_.point(v)[i] - bc.centre[i], 2);
        factor *= std::max(0.0, 1 - r2 / (bc.radius * bc.radius));
      }
      factor *= bc.waveform.factor(time);
    }
    for (int i = 0; i < dim; ++i) {
      const double value = bc.type == BoundaryCondition::Type::velocity ? factor * bc.value[i] : 0;
      COAPT_PETSC_CHECK(
          VecSetValue(fluid_->state(), mesh_.global_vertex[v] * n + i, value, INSERT_VALUES));
    }
  }
  COAPT_PETSC_CHECK(VecAssemblyBegin(fluid_->state()));
  COAPT_PETSC_CHECK(VecAssemblyEnd(fluid_->state()));
  fem::update_ghosts(fluid_->state());
}

void FluidModel::write_vtk(run::RunOutput& output, double time, const std::vector<io::Field>& extra,
                           const std::string& name) {
  const int dim = mesh_.dim, n = dim + 1;
  auto reaction = fluid_->vertex_reactions(force_level());  // assembles: before the state is read
  std::vector<double> velocity(static_cast<std::size_t>(mesh_.n_vertices()) * dim),
      pressure(static_cast<std::size_t>(mesh_.n_vertices()));
  {
    fem::LocalValues state(fluid_->state());
    for (int v = 0; v < mesh_.n_vertices(); ++v) {
      for (int i = 0; i < dim; ++i)
        velocity[static_cast<std::size_t>(v) * dim + i] =
            state[static_cast<std::size_t>(v) * n + i];
      pressure[v] = state[static_cast<std::size_t>(v) * n + dim];
    }
  }
  std::vector<io::Field> fields = {
      {"velocity", dim, io::Field::Location::vertex, velocity},
      {"pressure", 1, io::Field::Location::vertex, pressure},
      {"reaction", dim, io::Field::Location::vertex, std::move(reaction)},
  };
  fields.insert(fields.end(), extra.begin(), extra.end());
  output.vtk(name).write(mesh_, time, fields);
}

std::string FluidModel::boundary_group_names() const {
  std::string names;
  for (const auto& group : mesh_.groups)
    if (group.dim == mesh_.dim - 1) names += (names.empty() ? "" : ", ") + group.name;
  return names.empty() ? "it has none" : "it has: " + names;
}

}  // namespace coapt::fluid
