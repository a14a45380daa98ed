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
#include "coapt/fluid/fluid_model.hpp"
#include "coapt/fluid/kernels.hpp"
#include "coapt/solid/dynamics.hpp"

namespace coapt::fluid {
namespace {

using config::Bounds;

struct Benchmark {
  std::string type = "none";  ///< none | cavity | cylinder | obstacle | windkessel
  // windkessel: the outlet whose RCR relation is checked, the period of the inflow
  std::string outlet;
  double period = 0;
  // cavity: reference centreline tables (u(0.5, y), v(x, 0.5)), lid speed
  std::vector<double> reference_y, reference_u, reference_x, reference_v;
  int profile_points = 129;
  // cylinder (coefficients) and obstacle (forces): body group, normalisation, pressure
  // probes, reference values, start of the oscillation statistics of transient runs; height
  // is the span H of a 3D body
  std::string body;
  double mean_velocity = 1, diameter = 1, height = 1;
  std::string height_given;  ///< where the case sets benchmark.height ("" when it does not)
  std::vector<double> pressure_points;  ///< x_A, y_A, x_B, y_B: Δp = p(A) − p(B)
  double reference_drag = 0, reference_lift = 0, reference_pressure_difference = 0;
  double statistics_from = 0;  ///< [s]
};

/// The case: the fluid keys (FluidModel), the time settings and the benchmark.
struct Parameters {
  FluidCase fluid;
  TimeSettings time;
  Benchmark benchmark;
  bool write_vtk = true;
  int vtk_interval = 0;         ///< transient: VTK every this many steps (0: the last step only)
  int checkpoint_interval = 0;  ///< transient: a checkpoint every this many steps (0: none)
};

Parameters read(const config::Section& root) {
  Parameters p;
  p.fluid = FluidCase::read(root, root.section("fluid", "fluid properties and solver settings"));
  p.time = TimeSettings::read(root);

  auto benchmark = root.section("benchmark", "benchmark quantities written to summary.json");
  auto& b = p.benchmark;
  b.type = benchmark.choice(
      "type", "none", {"none", "cavity", "cylinder", "obstacle", "windkessel"},
      {"",
       "none | cavity (centreline profiles) | cylinder (force coefficients) | obstacle "
       "(forces) | windkessel (RCR check)"});
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
  } else if (b.type == "cylinder" || b.type == "obstacle") {
    b.body = benchmark.require<std::string>("body", {"", "boundary group of the body"});
    if (b.type == "cylinder") {
      b.mean_velocity = benchmark.require<double>(
          "mean_velocity", {"m/s", "Ū of c = 2F/(ρŪ²D)", Bounds::positive()});
      b.diameter =
          benchmark.require<double>("diameter", {"m", "D of c = 2F/(ρŪ²D)", Bounds::positive()});
      b.height = benchmark.get<double>(
          "height", 1.0, {"m", "3D: the span H in c = 2F/(ρŪ²DH)", Bounds::positive()});
      if (benchmark.has("height")) b.height_given = benchmark.located("height");
    }
    b.pressure_points = benchmark.get<std::vector<double>>(
        "pressure_points", {}, {"m", "x_A, y_A, x_B, y_B: Δp = p(A) − p(B) (steady runs)"});
    if (!b.pressure_points.empty() && b.pressure_points.size() != 4)
      benchmark.fail("pressure_points", "give 4 numbers: x_A, y_A, x_B, y_B (2D)");
    b.statistics_from = benchmark.get<double>(
        "statistics_from", 0.0,
        {"s", "transient runs: the last-period statistics use the steps from this time on",
         Bounds::non_negative()});
    auto reference = benchmark.section("reference", "published values (relative errors)");
    if (b.type == "cylinder") {
      b.reference_drag = reference.get<double>("drag_coefficient", 0.0, {"", "c_D (0: none)"});
      b.reference_lift = reference.get<double>("lift_coefficient", 0.0, {"", "c_L (0: none)"});
      b.reference_pressure_difference =
          reference.get<double>("pressure_difference", 0.0, {"Pa", "Δp (0: none)"});
    } else {
      b.reference_drag =
          reference.get<double>("drag", 0.0, {"N/m", "drag force (per unit depth; 0: none)"});
      b.reference_lift =
          reference.get<double>("lift", 0.0, {"N/m", "lift force (per unit depth; 0: none)"});
    }
  }
  auto output = root.section("output", "what the run writes");
  p.write_vtk = output.get<bool>("vtk", true, {"", "write velocity and pressure as VTK"});
  p.vtk_interval =
      output.get<int>("vtk_interval", 0,
                      {"", "transient: VTK every this many time steps (0: only at the end)",
                       Bounds::closed(0, 1000000)});
  p.checkpoint_interval =
      output.get<int>("checkpoint_interval", 0,
                      {"", "transient: time steps between checkpoints for --restart (0: none)",
                       Bounds::closed(0, 1000000)});
  return p;
}

class FlowProblem final : public run::Problem {
 public:
  FlowProblem(const config::Section& root, MPI_Comm comm)
      : parameters_(read(root)),
        comm_(comm),
        model_(parameters_.fluid, comm),
        mesh_(model_.mesh()) {
    const int dim = mesh_.dim;
    const auto& b = parameters_.benchmark;
    if (b.type == "cylinder" || b.type == "obstacle")
      body_tag_ = model_.boundary_tag(b.body, "benchmark.body");
    if (!b.pressure_points.empty() && !parameters_.time.steady)
      throw InputError("benchmark.pressure_points: Δp is reported for steady runs only");
    if (b.type == "windkessel") {
      const auto& outlets = parameters_.fluid.outlets;
      for (std::size_t k = 0; k < outlets.size(); ++k)
        if (outlets[k].group == b.outlet && outlets[k].type == OutletCondition::Type::windkessel)
          benchmark_outlet_ = static_cast<int>(k);
      if (benchmark_outlet_ < 0)
        throw InputError(fmt::format(
            "benchmark.outlet: '{}' is not a windkessel outlet of `outlets`", b.outlet));
      if (parameters_.time.steady)
        throw InputError("benchmark.type: windkessel needs a transient run (time.steady: false)");
    }
    if ((b.type == "cavity" || !b.pressure_points.empty()) && dim != 2)
      throw InputError("benchmark: the cavity profiles and pressure probes are 2D quantities");
    if (!b.height_given.empty() && dim != 3)
      throw InputError(fmt::format(
          "{}: the span H is for 3D bodies (2D coefficients are per unit depth)", b.height_given));
  }

  void describe() const override {
    model_.describe(
        fmt::format("navier_stokes: {}", parameters_.time.steady ? "steady" : "transient"));
  }

  /// Transient runs continue from a checkpoint of an earlier run (written every
  /// output.checkpoint_interval steps): the BDF history, the Windkessels, the step, and the
  /// histories the benchmark needs. The reader must live until run() returns.
  void restart_from(const run::CheckpointReader& checkpoint) override {
    if (parameters_.time.steady)
      throw InputError(fmt::format("--restart {}: a steady flow run has no checkpoints",
                                   checkpoint.directory().string()));
    const auto& state = checkpoint.state();
    const std::string kind = state.contains("problem") ? state.at("problem").as_string() : "solid";
    if (kind != "navier_stokes")
      throw InputError(
          fmt::format("--restart {}: a checkpoint of a '{}' run, this case is "
                      "navier_stokes",
                      checkpoint.directory().string(), kind));
    restart_ = &checkpoint;
  }

  void run(run::RunOutput& output) override {
    describe();
    model_.start(0.0);
    const auto& p = parameters_;
    int newton_total = 0, linear_total = 0;
    if (p.time.steady) {
      NewtonReport report;
      {
        ScopedTimer timer(output.timers(), "solve");
        report = model_.solve_steady("steady solve");
      }
      newton_total = report.iterations;
      linear_total = report.linear_iterations;
      log::info("steady: {} Newton iterations, {} linear iterations, residual {:.3e} -> {:.3e}",
                report.iterations, report.linear_iterations, report.residual_history.front(),
                report.residual_history.back());
      log::info("steady: Newton residuals {:.3e}", fmt::join(report.residual_history, ", "));
      record_step(output, 0.0, report);
    } else {
      const int n_steps = p.time.n_steps();
      int first_step = 1;
      if (restart_) {
        read_checkpoint(*restart_);
        first_step = model_.steps() + 1;
        log::info("continuing after step {} (t = {:g} s)", model_.steps(), model_.time());
      }
      Progress progress(n_steps, p.time.end_time, model_.time());
      for (int step = first_step; step <= n_steps; ++step) {
        const double dt = p.time.step_from(model_.time());
        model_.begin_step(dt);
        const double time = model_.time();
        NewtonReport report;
        try {
          ScopedTimer timer(output.timers(), "solve");
          report = model_.solve(fmt::format("step {} (t = {:g} s)", step, time));
        } catch (const ConvergenceError&) {
          keep_last_good_state(output, step - 1);
          throw;
        }
        if (step <= 2 || step == n_steps)
          log::info("step {}: Newton residuals {:.3e}", step,
                    fmt::join(report.residual_history, ", "));
        model_.commit_step();
        newton_total += report.iterations;
        linear_total += report.linear_iterations;
        record_step(output, time, report);
        progress.step(
            step, time,
            fmt::format("newton {}, ksp {}", report.iterations, report.linear_iterations));
        if (p.write_vtk && p.vtk_interval > 0 && step % p.vtk_interval == 0) {
          ScopedTimer timer(output.timers(), "output");
          model_.write_vtk(output, time);
          last_vtk_step_ = step;
        }
        if (p.checkpoint_interval > 0 && step % p.checkpoint_interval == 0) {
          ScopedTimer timer(output.timers(), "checkpoint");
          write_checkpoint(output);
        }
      }
    }
    model_.write_windkessel_states(output);
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = newton_total;
    iterations["linear"] = linear_total;
    {
      ScopedTimer timer(output.timers(), "benchmark");
      benchmark(output);
    }
    if (p.write_vtk && (p.time.steady || last_vtk_step_ != model_.steps())) {
      ScopedTimer timer(output.timers(), "output");
      model_.write_vtk(output, p.time.steady ? 0.0 : model_.time());
    }
  }

 private:
  /// After the Newton solve of a step failed (ConvergenceError, which the caller rethrows):
  /// the trial state is dropped, and the run folder keeps the last committed state next to
  /// the failure: its benchmark figures, its VTK fields (unless that step's are written
  /// already) and a checkpoint, so that `--restart DIR` (with a smaller `time.step`, say)
  /// continues from it. Nothing of the failed trial state is written.
  void keep_last_good_state(run::RunOutput& output, int last_step) {
    const auto& p = parameters_;
    model_.restore_step();
    model_.write_windkessel_states(output);
    try {
      benchmark(output);
    } catch (const Error& error) {
      // the step's failure is what the run reports; a benchmark that cannot be evaluated on
      // the short history is recorded beside it
      output.summary()["benchmark_error"] = error.what();
    }
    if (p.write_vtk && last_vtk_step_ != last_step) model_.write_vtk(output, model_.time());
    write_checkpoint(output);
    output.keep_last_good_state(last_step, model_.time());
  }

  /// The model's history and the benchmark histories into output/checkpoint.
  void write_checkpoint(run::RunOutput& output) const {
    run::CheckpointWriter writer(comm_, output.directory() / "checkpoint");
    auto& state = writer.state();
    state["problem"] = "navier_stokes";
    model_.write_checkpoint(writer);
    auto& histories = state["histories"];
    histories["outlet_time"] = io::Json::array_of(history_time_);
    histories["outlet_flow"] = io::Json::array_of(history_flow_);
    histories["outlet_pressure"] = io::Json::array_of(history_pressure_);
    histories["body_time"] = io::Json::array_of(history_body_time_);
    histories["drag"] = io::Json::array_of(history_drag_);
    histories["lift"] = io::Json::array_of(history_lift_);
    writer.commit();
  }

  void read_checkpoint(const run::CheckpointReader& reader) {
    model_.read_checkpoint(reader);
    const auto& histories = reader.state().at("histories");
    const auto doubles = [&](const char* key) {
      std::vector<double> values;
      for (const auto& value : histories.at(key).as_array()) values.push_back(value.as_double());
      return values;
    };
    history_time_ = doubles("outlet_time");
    history_flow_ = doubles("outlet_flow");
    history_pressure_ = doubles("outlet_pressure");
    history_body_time_ = doubles("body_time");
    history_drag_ = doubles("drag");
    history_lift_ = doubles("lift");
    const bool outlet_history = history_time_.size() == static_cast<std::size_t>(model_.steps());
    if ((benchmark_outlet_ >= 0 && !outlet_history) ||
        (benchmark_outlet_ < 0 && !history_time_.empty()) ||
        (body_tag_ < 0 && !history_body_time_.empty()))
      throw InputError(fmt::format(
          "--restart {}: the checkpoint's benchmark histories are not those of this case's "
          "benchmark.type {}",
          reader.directory().string(), parameters_.benchmark.type));
  }

  /// One row of series.csv: iterations, the body's force coefficients, the flows.
  void record_step(run::RunOutput& output, double time, const NewtonReport& report) {
    auto& series = output.series();
    series.add("time", time);
    series.add("newton_iterations", report.iterations);
    series.add("linear_iterations", report.linear_iterations);
    series.add("residual", report.residual_history.back());
    if (body_tag_ >= 0) {
      const auto force = model_.boundary_force(body_tag_);
      const double scale = force_scale();
      const bool coefficients = parameters_.benchmark.type == "cylinder";
      series.add(coefficients ? "drag_coefficient" : "drag", scale * force[0]);
      series.add(coefficients ? "lift_coefficient" : "lift", scale * force[1]);
      if (!parameters_.time.steady && time >= parameters_.benchmark.statistics_from) {
        history_body_time_.push_back(time);
        history_drag_.push_back(scale * force[0]);
        history_lift_.push_back(scale * force[1]);
      }
    }
    model_.record_flows(series);
    if (benchmark_outlet_ >= 0) {
      const auto k = static_cast<std::size_t>(benchmark_outlet_);
      history_time_.push_back(time);
      history_flow_.push_back(model_.outlet_flow(k));
      history_pressure_.push_back(model_.outlet_pressure(k));
    }
    series.end_row();
  }

  /// 2/(ρŪ²D) (2D) or 2/(ρŪ²DH) (3D) for the cylinder's coefficients, 1 for the obstacle's
  /// forces.
  double force_scale() const {
    const auto& b = parameters_.benchmark;
    if (b.type != "cylinder") return 1.0;
    const double span = mesh_.dim == 3 ? b.height : 1.0;
    return 2.0 / (parameters_.fluid.fluid.density * b.mean_velocity * b.mean_velocity * b.diameter *
                  span);
  }

  /// Transient runs with a body: drag and lift (coefficients or forces) over their last full
  /// period after statistics_from (solid::last_period: mean = (max + min)/2, amplitude =
  /// (max − min)/2, frequency from successive upward mid-level crossings), as
  /// `drag…`/`lift…` objects {mean, amplitude, frequency, periods, final}; for the cylinder also
  /// c_L,max = mean + amplitude of the lift, c_D,max (over the last lift period) and the
  /// Strouhal number St = D f_L / Ū from the lift frequency (Schäfer & Turek 1996, 2D-2).
  void oscillation_benchmark(io::Json& json) {
    const auto& b = parameters_.benchmark;
    const bool coefficients = b.type == "cylinder";
    const auto number = [](double x) { return std::isfinite(x) ? io::Json(x) : io::Json(); };
    const auto summarise = [&](const std::string& key, const std::vector<double>& values) {
      const auto summary = solid::last_period(history_body_time_, values);
      auto& entry = json[key];
      entry["mean"] = number(summary.mean);
      entry["amplitude"] = number(summary.amplitude);
      entry["frequency"] = number(summary.frequency);
      entry["periods"] = summary.periods;
      entry["final"] = values.empty() ? io::Json() : io::Json(values.back());
      log::info(
          "{}: mean {:.6g}, amplitude {:.6g}, frequency {:.6g} Hz ({} full period(s) after "
          "t = {:g} s)",
          key, summary.mean, summary.amplitude, summary.frequency, summary.periods,
          b.statistics_from);
      return summary;
    };
    summarise(coefficients ? "drag_coefficient" : "drag", history_drag_);
    const auto lift = summarise(coefficients ? "lift_coefficient" : "lift", history_lift_);
    if (!coefficients) return;
    // c_D oscillates at twice the lift frequency, with alternating peaks when the street is not
    // exactly symmetric: its maximum is taken over the last lift period (the largest sample
    // there, refined by the parabola through it and its neighbours).
    double drag_max = std::numeric_limits<double>::quiet_NaN();
    if (lift.periods > 0) {
      const auto& t = history_body_time_;
      const double start = t.back() - 1.0 / lift.frequency;
      std::size_t best = t.size() - 1;
      for (std::size_t k = 0; k < t.size(); ++k)
        if (t[k] >= start && history_drag_[k] > history_drag_[best]) best = k;
      drag_max = best > 0 && best + 1 < t.size()
                     ? solid::detail::parabola_vertex(t, history_drag_, best).second
                     : history_drag_[best];
    }
    json["drag_coefficient_max"] = number(drag_max);
    json["lift_coefficient_max"] = number(lift.mean + lift.amplitude);
    json["strouhal"] = number(b.diameter * lift.frequency / b.mean_velocity);
    log::info("c_D,max = {:.6f}, c_L,max = {:.6f}, St = {:.6f}", drag_max,
              lift.mean + lift.amplitude, b.diameter * lift.frequency / b.mean_velocity);
  }

  void benchmark(run::RunOutput& output) {
    const auto& b = parameters_.benchmark;
    auto& json = output.summary()["benchmark"];
    json["cells"] = static_cast<std::int64_t>(mesh_.n_global_cells);
    json["vertices"] = static_cast<std::int64_t>(mesh_.n_global_vertices);
    const int n = mesh_.dim + 1;
    if ((b.type == "cylinder" || b.type == "obstacle") && !parameters_.time.steady) {
      oscillation_benchmark(json);
    } else if (b.type == "obstacle") {
      const auto force = model_.boundary_force(body_tag_);
      json["drag"] = force[0];
      json["lift"] = force[1];
      log::info("drag = {:.8g} N/m, lift = {:.8g} N/m", force[0], force[1]);
      if (b.reference_drag != 0) json["drag_error"] = std::abs(force[0] / b.reference_drag - 1);
      if (b.reference_lift != 0) json["lift_error"] = std::abs(force[1] / b.reference_lift - 1);
    } else if (b.type == "cylinder") {
      const auto force = model_.boundary_force(body_tag_);
      const double scale = force_scale();
      const double drag = scale * force[0], lift = scale * force[1];
      json["drag_force"] = force[0];
      json["lift_force"] = force[1];
      json["drag_coefficient"] = drag;
      json["lift_coefficient"] = lift;
      log::info("c_D = {:.8f}, c_L = {:.8f}", drag, lift);
      if (b.reference_drag != 0) json["drag_error"] = std::abs(drag / b.reference_drag - 1);
      if (b.reference_lift != 0) json["lift_error"] = std::abs(lift / b.reference_lift - 1);
      if (!b.pressure_points.empty()) {
        const auto p = values_at(mesh_, model_.state(), n, mesh_.dim, b.pressure_points);
        const double difference = p[0] - p[1];
        json["pressure_difference"] = difference;
        log::info("Delta p = {:.8f} Pa", difference);
        if (b.reference_pressure_difference != 0)
          json["pressure_difference_error"] =
              std::abs(difference / b.reference_pressure_difference - 1);
      }
    } else if (b.type == "cavity") {
      cavity_profiles(output, json);
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
    const auto& wk =
        parameters_.fluid.outlets[static_cast<std::size_t>(benchmark_outlet_)].windkessel;
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

  void cavity_profiles(run::RunOutput& output, io::Json& json) {
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
    const auto u = values_at(mesh_, model_.state(), n, 0, line_u);
    const auto v = values_at(mesh_, model_.state(), n, 1, line_v);
    const auto u_table = values_at(mesh_, model_.state(), n, 0, table_u);
    const auto v_table = values_at(mesh_, model_.state(), n, 1, table_v);
    double error_u = 0, error_v = 0;
    for (std::size_t k = 0; k < u_table.size(); ++k)
      error_u = std::max(error_u, std::abs(u_table[k] - b.reference_u[k]));
    for (std::size_t k = 0; k < v_table.size(); ++k)
      error_v = std::max(error_v, std::abs(v_table[k] - b.reference_v[k]));
    if (!b.reference_u.empty()) json["max_error_u"] = error_u;
    if (!b.reference_v.empty()) json["max_error_v"] = error_v;
    if (!b.reference_u.empty() || !b.reference_v.empty())
      log::info("centrelines: max |u - u_ref| = {:.4e}, max |v - v_ref| = {:.4e}", error_u,
                error_v);
    // The extrema of the centreline profiles (the primary vortex's strength), each refined by
    // the parabola through the extreme sample and its neighbours.
    const auto extremum = [&](const std::vector<double>& line, int coordinate,
                              const std::vector<double>& values, bool maximum, const char* key,
                              const char* position_key) {
      std::vector<double> s(values.size());
      for (std::size_t k = 0; k < s.size(); ++k) s[k] = line[2 * k + coordinate];
      std::size_t best = 0;
      for (std::size_t k = 1; k < values.size(); ++k)
        if (maximum ? values[k] > values[best] : values[k] < values[best]) best = k;
      auto vertex = std::pair<double, double>{s[best], values[best]};
      if (best > 0 && best + 1 < values.size())
        vertex = solid::detail::parabola_vertex(s, values, best);
      json[key] = vertex.second;
      json[position_key] = vertex.first;
      log::info("{} = {:.6f} at {} = {:.4f}", key, vertex.second, position_key, vertex.first);
    };
    extremum(line_u, 1, u, false, "u_min", "u_min_y");
    extremum(line_v, 0, v, true, "v_max", "v_max_x");
    extremum(line_v, 0, v, false, "v_min", "v_min_x");
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

  const Parameters parameters_;
  MPI_Comm comm_;
  FluidModel model_;
  const mesh::Mesh& mesh_;
  int body_tag_ = -1;
  int benchmark_outlet_ = -1;  ///< the outlet of the windkessel benchmark
  std::vector<double> history_time_, history_flow_, history_pressure_;  ///< of that outlet
  /// Transient body forces from benchmark.statistics_from on: times, drag and lift (the
  /// benchmark's coefficients or forces).
  std::vector<double> history_body_time_, history_drag_, history_lift_;
  const run::CheckpointReader* restart_ = nullptr;
  int last_vtk_step_ = -1;  ///< transient: the last step whose VTK fields are written
};

}  // namespace

std::unique_ptr<run::Problem> create_flow_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<FlowProblem>(root, comm);
}

}  // namespace coapt::fluid
