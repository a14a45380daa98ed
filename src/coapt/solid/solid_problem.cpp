// The `problem: solid` driver over SolidModel: per load step one static solve at load factor
// s = step/steps, or a Newmark time loop recording probes and energies per step, then the
// benchmark quantities.
#include "coapt/solid/solid_problem.hpp"

#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "coapt/core/log.hpp"
#include "coapt/core/progress.hpp"
#include "coapt/core/timer.hpp"
#include "coapt/io/json.hpp"
#include "coapt/solid/dynamics.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::solid {
namespace {

constexpr const char* kComponentNames[3] = {"x", "y", "z"};

class SolidProblem final : public run::Problem {
 public:
  SolidProblem(const config::Section& root, MPI_Comm comm) : solid_(root, comm) {}

  void describe() const override { solid_.describe(); }

  /// Newmark runs continue from a checkpoint of an earlier run (written every
  /// output.checkpoint_interval steps): the committed state, the step, and what the summary
  /// needs (energy bookkeeping, probe histories). The reader must live until run() returns.
  void restart_from(const run::CheckpointReader& checkpoint) override {
    if (!parameters().time.dynamic)
      throw InputError(fmt::format("--restart {}: a quasi-static solid run has no checkpoints",
                                   checkpoint.directory().string()));
    restart_ = &checkpoint;
  }

  void run(run::RunOutput& output) override {
    describe();
    if (solid_.parameters().time.dynamic)
      solve_dynamic(output);
    else
      solve_static(output);
  }

 private:
  const SolidParameters& parameters() const { return solid_.parameters(); }
  int dim() const { return solid_.dim(); }

  /// "tip_displacement_y" for probe p, component i.
  std::string probe_key(std::size_t p, int i) const {
    return parameters().probes[p].name + "_displacement_" + kComponentNames[i];
  }

  void write_mesh_figures(io::Json& benchmark) const {
    benchmark["cells"] = static_cast<std::int64_t>(solid_.mesh().n_global_cells);
    benchmark["vertices"] = static_cast<std::int64_t>(solid_.mesh().n_global_vertices);
    benchmark["level"] = parameters().mesh.level;
  }

  void solve_static(run::RunOutput& output) {
    const int steps = parameters().steps;
    int total_newton = 0, total_linear = 0;
    for (int step = 1; step <= steps; ++step) {
      const double factor = static_cast<double>(step) / steps;
      const auto report = solid_.solve_static(
          factor, output, fmt::format("load step {}/{} (load factor {:g})", step, steps, factor));
      total_newton += report.newton_iterations;
      total_linear += report.linear_iterations;
      const auto values = solid_.probe_values();
      auto& series = output.series();
      series.add("step", step);
      series.add("load_factor", factor);
      series.add("newton_iterations", report.newton_iterations);
      series.add("residual_norm", report.norm());
      for (std::size_t p = 0; p < values.size(); ++p)
        for (int i = 0; i < dim(); ++i) series.add(probe_key(p, i), values[p][i]);
      series.end_row();
      if (parameters().write_vtk) solid_.write_vtk(output, factor);
    }

    const auto values = solid_.probe_values();
    auto& benchmark = output.summary()["benchmark"];
    for (std::size_t p = 0; p < values.size(); ++p)
      for (int i = 0; i < dim(); ++i) {
        benchmark[probe_key(p, i)] = values[p][i];
        log::info("{} = {:.8e} m", probe_key(p, i), values[p][i]);
      }
    write_mesh_figures(benchmark);
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = total_newton;
    iterations["linear"] = total_linear;
  }

  /// Newmark from the case's initial state; series.csv gets the probes and the energies
  /// (kinetic ½ vᵀMv, strain ∫ψ, work of the constant loads f_extᵀu) per step.
  void solve_dynamic(run::RunOutput& output) {
    const auto& time = parameters().time;
    solid_.initialize_dynamics(output);
    std::vector<double> times;
    std::vector<std::vector<double>> probe_history(parameters().probes.size() *
                                                   static_cast<std::size_t>(dim()));
    double initial_energy = 0, energy_scale = 0, largest_change = 0;
    const auto record = [&](int step, double t, int iterations) {
      const double kinetic = solid_.kinetic_energy(), strain = solid_.strain_energy();
      const double work = solid_.external_work();
      const double total = kinetic + strain - work;
      if (step == 0) initial_energy = total;
      energy_scale = std::max(energy_scale, kinetic + strain);
      largest_change = std::max(largest_change, std::abs(total - initial_energy));
      const auto values = solid_.probe_values();
      times.push_back(t);
      auto& series = output.series();
      series.add("step", step);
      series.add("time", t);
      for (std::size_t p = 0; p < values.size(); ++p)
        for (int i = 0; i < dim(); ++i) {
          series.add(probe_key(p, i), values[p][i]);
          probe_history[p * dim() + i].push_back(values[p][i]);
        }
      series.add("kinetic_energy", kinetic);
      series.add("strain_energy", strain);
      series.add("external_work", work);
      series.add("total_energy", total);
      series.add("newton_iterations", iterations);
      series.end_row();
    };
    int first_step = 1;
    if (restart_) {
      solid_.read_checkpoint(*restart_);
      const auto& state = restart_->state();
      const auto doubles = [](const io::Json& array) {
        std::vector<double> values;
        for (const auto& value : array.as_array()) values.push_back(value.as_double());
        return values;
      };
      first_step = static_cast<int>(state.at("step").as_int()) + 1;
      initial_energy = state.at("initial_energy").as_double();
      energy_scale = state.at("energy_scale").as_double();
      largest_change = state.at("largest_energy_change").as_double();
      times = doubles(state.at("times"));
      const auto& histories = state.at("probe_history");
      if (histories.size() != probe_history.size())
        throw InputError(
            fmt::format("--restart {}: the checkpoint has {} probe histories, the "
                        "case {}",
                        restart_->directory().string(), histories.size(), probe_history.size()));
      for (std::size_t k = 0; k < probe_history.size(); ++k)
        probe_history[k] = doubles(histories.at(k));
      log::info("continuing after step {} (t = {:g} s)", first_step - 1, times.back());
    } else {
      record(0, 0.0, 0);
      if (parameters().write_vtk) solid_.write_vtk(output, 0.0);
    }
    const auto checkpoint = [&](int step, double t) {
      ScopedTimer timer(output.timers(), "checkpoint");
      run::CheckpointWriter writer(solid_.comm(), output.directory() / "checkpoint");
      auto& state = writer.state();
      state["step"] = step;
      state["time"] = t;
      state["initial_energy"] = initial_energy;
      state["energy_scale"] = energy_scale;
      state["largest_energy_change"] = largest_change;
      state["times"] = io::Json::array_of(times);
      auto& histories = state["probe_history"] = io::Json::array();
      for (const auto& history : probe_history) histories.push_back(io::Json::array_of(history));
      solid_.write_checkpoint(writer);
      writer.commit();
    };

    int total_newton = 0, total_linear = 0;
    Progress progress(time.n_steps, time.end_time);
    for (int step = first_step; step <= time.n_steps; ++step) {
      const double t = step * time.step;
      const auto report = solid_.step(t, time.step, output);
      solid_.commit();
      total_newton += report.newton_iterations;
      total_linear += report.linear_iterations;
      record(step, t, report.newton_iterations);
      progress.step(
          step, t,
          fmt::format("newton {} (|R| {:.2e} -> {:.2e}), ksp {}", report.newton_iterations,
                      report.history.front(), report.norm(), report.linear_iterations));
      if (parameters().write_vtk && step % parameters().vtk_interval == 0)
        solid_.write_vtk(output, t);
      if (parameters().checkpoint_interval > 0 && step % parameters().checkpoint_interval == 0)
        checkpoint(step, t);
    }

    auto& benchmark = output.summary()["benchmark"];
    for (std::size_t p = 0; p < parameters().probes.size(); ++p)
      for (int i = 0; i < dim(); ++i) {
        const std::string key = (p == 0 ? std::string() : parameters().probes[p].name + "_") +
                                "displacement_" + kComponentNames[i];
        const OscillationSummary summary = last_period(times, probe_history[p * dim() + i]);
        const auto number = [](double x) { return std::isfinite(x) ? io::Json(x) : io::Json(); };
        auto& entry = benchmark[key];
        entry["mean"] = number(summary.mean);
        entry["amplitude"] = number(summary.amplitude);
        entry["frequency"] = number(summary.frequency);
        entry["periods"] = summary.periods;
        entry["final"] = probe_history[p * dim() + i].back();
        log::info(
            "{} {}: mean {:.6e} m, amplitude {:.6e} m, frequency {:.6g} Hz ({} full "
            "period(s) seen)",
            parameters().probes[p].name, key, summary.mean, summary.amplitude, summary.frequency,
            summary.periods);
      }
    const double drift = energy_scale > 0 ? largest_change / energy_scale : 0.0;
    benchmark["energy_initial"] = initial_energy;
    benchmark["energy_scale"] = energy_scale;
    benchmark["energy_max_relative_change"] = drift;
    log::info("total energy: initial {:.10e}, max |E - E0| / max(kinetic + strain) = {:.3e}",
              initial_energy, drift);
    write_mesh_figures(benchmark);
    benchmark["time_step"] = time.step;
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = total_newton;
    iterations["linear"] = total_linear;
  }

  SolidModel solid_;
  const run::CheckpointReader* restart_ = nullptr;
};

}  // namespace

std::unique_ptr<run::Problem> create_solid_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<SolidProblem>(root, comm);
}

}  // namespace coapt::solid
