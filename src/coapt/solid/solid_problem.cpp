// The `problem: solid` driver over SolidModel: per load step one static solve at load factor
// s = step/steps, or a Newmark time loop recording probes and energies per step, then the
// benchmark quantities.
#include "coapt/solid/solid_problem.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <petscsys.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "coapt/contact/solid_contact.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/core/progress.hpp"
#include "coapt/core/timer.hpp"
#include "coapt/io/json.hpp"
#include "coapt/solid/closed_form.hpp"
#include "coapt/solid/dynamics.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::solid {
namespace {

constexpr const char* kComponentNames[3] = {"x", "y", "z"};

/// `impacts: {body: ball}`: the body whose impacts (find_impacts) a dynamic contact run
/// reports; empty: none.
std::string read_impact_body(const config::Section& root) {
  if (!root.has("impacts")) return {};
  const auto section = root.section("impacts", "impacts of a body against the others");
  return section.require<std::string>(
      "body", {"", "the body whose rebound angles and energy loss per impact are reported"});
}

class SolidProblem final : public run::Problem {
 public:
  SolidProblem(const config::Section& root, MPI_Comm comm)
      : contact_parameters_(contact::read_solid_contact(root)),
        hertz_(contact::HertzParameters::read(root)),
        patch_test_(contact::PatchTestParameters::read(root)),
        impact_body_name_(read_impact_body(root)),
        solid_(root, comm) {
    if (contact_parameters_.enabled()) {
      contact_ = std::make_unique<contact::ContactHook>(contact_parameters_, solid_);
      solid_.set_hook(contact_.get());
    }
    if (parameters().time.contact_stabilized && !contact_)
      log::warn(
          "time.scheme contact_stabilized_newmark without a contact section: Newmark with a "
          "lumped mass");
    // An unknown reaction boundary is an input error now, not after the first load step.
    for (const auto& boundary : parameters().reaction_boundaries)
      (void)solid_.reaction_force(boundary);
    if (!impact_body_name_.empty()) {
      const auto section = root.section("impacts", "impacts of a body against the others");
      if (!parameters().time.dynamic || !contact_)
        section.fail("body", "impacts are measured in dynamic runs with a contact section");
      const auto& bodies = parameters().bodies;
      for (std::size_t b = 0; b < bodies.size(); ++b)
        if (bodies[b].name == impact_body_name_) impact_body_ = static_cast<int>(b);
      if (impact_body_ < 0)
        section.fail("body", fmt::format("no body named '{}' in `bodies`", impact_body_name_));
    }
  }

  void describe() const override {
    solid_.describe();
    if (contact_)
      log::info("contact (frictionless mortar, dual multipliers, semi-smooth Newton): {}",
                contact_->constraints().describe());
  }

  /// Newmark runs continue from a checkpoint of an earlier run (written every
  /// output.checkpoint_interval steps): the committed state, the step, and what the summary
  /// needs (energy bookkeeping, probe histories). The reader must live until run() returns.
  void restart_from(const run::CheckpointReader& checkpoint) override {
    if (!parameters().time.dynamic)
      throw InputError(fmt::format("--restart {}: a quasi-static solid run has no checkpoints",
                                   checkpoint.directory().string()));
    const auto& state = checkpoint.state();
    if (state.contains("problem") && state.at("problem").as_string() != "solid")
      throw InputError(fmt::format("--restart {}: a checkpoint of a '{}' run, this case is solid",
                                   checkpoint.directory().string(),
                                   state.at("problem").as_string()));
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

  /// "reaction_base_y" for a boundary, component i.
  std::string reaction_key(const std::string& boundary, int i) const {
    return "reaction_" + boundary + "_" + kComponentNames[i];
  }

  /// Per-step figures of a static run and the contact extremes over all its load steps.
  struct StepHistory {
    std::vector<int> newton_iterations, active_nodes, active_set_changes;
    double max_penetration = 0, max_complementarity = 0, max_open_pressure = 0;
    double min_active_pressure = std::numeric_limits<double>::infinity();

    void add(const contact::ContactStatus& status, int changes) {
      active_nodes.push_back(status.active);
      active_set_changes.push_back(changes);
      max_penetration = std::max(max_penetration, status.max_penetration);
      max_complementarity = std::max(max_complementarity, status.max_complementarity);
      max_open_pressure = std::max(max_open_pressure, status.max_open_pressure);
      if (status.active > 0)
        min_active_pressure = std::min(min_active_pressure, status.min_active_pressure);
    }
    void write(io::Json& benchmark) const {
      benchmark["contact_active_nodes_per_step"] = io::Json::array_of(active_nodes);
      benchmark["contact_active_set_changes_per_step"] = io::Json::array_of(active_set_changes);
      benchmark["contact_max_penetration_over_steps"] = max_penetration;
      benchmark["contact_max_complementarity_over_steps"] = max_complementarity;
      benchmark["contact_max_open_pressure_over_steps"] = max_open_pressure;
      benchmark["contact_min_active_pressure_over_steps"] =
          std::isfinite(min_active_pressure) ? min_active_pressure : 0.0;
    }
  };

  void write_mesh_figures(io::Json& benchmark) const {
    benchmark["cells"] = static_cast<std::int64_t>(solid_.mesh().n_global_cells);
    benchmark["vertices"] = static_cast<std::int64_t>(solid_.mesh().n_global_vertices);
    benchmark["level"] = parameters().mesh.level;
  }

  void solve_static(run::RunOutput& output) {
    const int steps = parameters().steps;
    int total_newton = 0, total_linear = 0;
    StepHistory history;
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
      for (const auto& boundary : parameters().reaction_boundaries) {
        const auto reaction = solid_.reaction_force(boundary);
        for (int i = 0; i < dim(); ++i)
          series.add(reaction_key(boundary, i), reaction[static_cast<std::size_t>(i)]);
      }
      history.newton_iterations.push_back(report.newton_iterations);
      if (contact_) {
        contact_->add_series(output);
        contact_->log_status(fmt::format("load step {}/{}", step, steps));
        history.add(contact_->constraints().status(), contact_->active_set_change_iterations());
      }
      series.end_row();
      if (parameters().write_vtk) write_vtk(output, factor);
    }

    const auto values = solid_.probe_values();
    auto& benchmark = output.summary()["benchmark"];
    for (std::size_t p = 0; p < values.size(); ++p)
      for (int i = 0; i < dim(); ++i) {
        benchmark[probe_key(p, i)] = values[p][i];
        log::info("{} = {:.8e} m", probe_key(p, i), values[p][i]);
      }
    write_mesh_figures(benchmark);
    write_closed_form_benchmark(solid_, benchmark);
    for (const auto& boundary : parameters().reaction_boundaries) {
      const auto reaction = solid_.reaction_force(boundary);
      for (int i = 0; i < dim(); ++i)
        benchmark[reaction_key(boundary, i)] = reaction[static_cast<std::size_t>(i)];
      log::info("reaction on '{}': ({:.8e}) N", boundary, fmt::join(reaction, ", "));
    }
    benchmark["newton_iterations_per_step"] = io::Json::array_of(history.newton_iterations);
    if (contact_) {
      write_contact_figures(benchmark);
      history.write(benchmark);
      contact_->write_nodes(output.directory() / "contact_nodes.csv", solid_.comm());
    }
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = total_newton;
    iterations["linear"] = total_linear;
  }

  /// The solid's VTU fields, with the contact pressure, gap and active set under contact.
  void write_vtk(run::RunOutput& output, double time) {
    if (contact_)
      solid_.write_vtk(output, time, contact_->fields());
    else
      solid_.write_vtk(output, time);
  }

  /// Contact state at the end, and the Hertz comparison when the case has `hertz:`.
  void write_contact_figures(io::Json& benchmark) const {
    const auto& status = contact_->constraints().status();
    benchmark["contact_active_nodes"] = status.active;
    benchmark["contact_total_force"] = status.total_force;
    for (int i = 0; i < dim(); ++i)
      benchmark[fmt::format("contact_force_{}", kComponentNames[i])] =
          status.force_vector[static_cast<std::size_t>(i)];
    benchmark["contact_min_active_pressure"] = status.min_active_pressure;
    benchmark["contact_max_penetration"] = status.max_penetration;
    benchmark["contact_max_complementarity"] = status.max_complementarity;
    benchmark["contact_max_open_pressure"] = status.max_open_pressure;
    benchmark["contact_gap_tolerance"] = status.gap_tolerance;
    benchmark["complementarity_constant"] = status.complementarity_constant;
    benchmark["contact_pressure_relative_spread"] =
        status.max_pressure > 0
            ? (status.max_pressure - status.min_active_pressure) / status.max_pressure
            : 0.0;
    if (patch_test_.enabled) {
      const double error = contact::pressure_error(contact_->constraints(), patch_test_.force);
      const double force_error =
          std::abs(status.total_force - patch_test_.force) / patch_test_.force;
      benchmark["contact_pressure_error"] = error;
      benchmark["contact_force_error"] = force_error;
      log::info(
          "patch test: pressure {:.10e} Pa (load / contact measure {:.10e}): max relative "
          "deviation {:.3e} over {} active nodes; force {:.10e} (load {:g}, relative error "
          "{:.3e})",
          status.max_pressure, patch_test_.force / status.contact_measure, error, status.active,
          status.total_force, patch_test_.force, force_error);
    }
    if (!hertz_.enabled) return;
    const auto measured = contact::measure_hertz(contact_->constraints(), hertz_.sphere);
    const std::string size = hertz_.sphere ? "contact_radius" : "contact_half_width";
    benchmark["max_pressure"] = measured.max_pressure;
    benchmark["max_pressure_analytic"] = hertz_.max_pressure();
    benchmark[size] = measured.contact_size;
    benchmark[size + "_analytic"] = hertz_.contact_size();
    benchmark["fitted_max_pressure"] = measured.fitted_pressure;
    benchmark["outermost_active_node"] = measured.outermost_active;
    const auto error = [](double value, double reference) {
      return std::abs(value - reference) / reference;
    };
    benchmark["max_pressure_error"] = error(measured.max_pressure, hertz_.max_pressure());
    benchmark["max_nominal_pressure"] = measured.max_nominal_pressure;
    benchmark["max_nominal_pressure_error"] =
        error(measured.max_nominal_pressure, hertz_.max_pressure());
    benchmark[size + "_error"] = error(measured.contact_size, hertz_.contact_size());
    log::info(
        "Hertz: max pressure {:.6e} Pa (analytic {:.6e}, error {:.3f} %), {} {:.6e} m "
        "(analytic {:.6e}, error {:.3f} %), {} active nodes; max nominal pressure {:.6e} Pa "
        "(error {:.3f} %)",
        measured.max_pressure, hertz_.max_pressure(),
        100 * error(measured.max_pressure, hertz_.max_pressure()), size, measured.contact_size,
        hertz_.contact_size(), 100 * error(measured.contact_size, hertz_.contact_size()),
        measured.active_nodes, measured.max_nominal_pressure,
        100 * error(measured.max_nominal_pressure, hertz_.max_pressure()));
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
      const auto motions = solid_.body_motion();
      for (const auto& motion : motions) {
        for (int i = 0; i < dim(); ++i)
          series.add(fmt::format("barycentre_{}_{}", kComponentNames[i], motion.name),
                     motion.barycentre[i]);
        for (int i = 0; i < dim(); ++i)
          series.add(fmt::format("momentum_{}_{}", kComponentNames[i], motion.name),
                     motion.momentum[i]);
        if (dim() == 2)
          series.add("angular_momentum_" + motion.name, motion.angular_momentum[2]);
        else
          for (int i = 0; i < 3; ++i)
            series.add(fmt::format("angular_momentum_{}_{}", kComponentNames[i], motion.name),
                       motion.angular_momentum[i]);
      }
      if (contact_) contact_->add_series(output);
      series.end_row();
      if (impact_body_ >= 0) {
        const auto& motion = motions[static_cast<std::size_t>(impact_body_)];
        std::array<double, 3> velocity{};
        for (int i = 0; i < 3; ++i)
          velocity[i] = motion.mass > 0 ? motion.momentum[i] / motion.mass : 0.0;
        impact_velocity_.push_back(velocity);
        impact_contact_.push_back(contact_->constraints().status().active > 0 ? 1 : 0);
        impact_energy_.push_back(total);
      }
    };
    int first_step = 1;
    if (restart_) {
      solid_.read_checkpoint(*restart_);
      if (contact_) contact_->read_checkpoint(*restart_, "contact_");
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
      if (impact_body_ >= 0) {
        const auto contact = doubles(state.at("impact_contact"));
        const auto velocity = doubles(state.at("impact_velocity"));
        impact_energy_ = doubles(state.at("impact_energy"));
        for (std::size_t k = 0; k < contact.size(); ++k) {
          impact_contact_.push_back(contact[k] != 0 ? 1 : 0);
          impact_velocity_.push_back({velocity[3 * k], velocity[3 * k + 1], velocity[3 * k + 2]});
        }
      }
      log::info("continuing after step {} (t = {:g} s)", first_step - 1, times.back());
    } else {
      record(0, 0.0, 0);
      if (parameters().write_vtk) write_vtk(output, 0.0);
    }
    const auto checkpoint = [&](int step, double t) {
      ScopedTimer timer(output.timers(), "checkpoint");
      run::CheckpointWriter writer(solid_.comm(), output.directory() / "checkpoint");
      auto& state = writer.state();
      state["problem"] = "solid";
      state["step"] = step;
      state["time"] = t;
      state["initial_energy"] = initial_energy;
      state["energy_scale"] = energy_scale;
      state["largest_energy_change"] = largest_change;
      state["times"] = io::Json::array_of(times);
      auto& histories = state["probe_history"] = io::Json::array();
      for (const auto& history : probe_history) histories.push_back(io::Json::array_of(history));
      if (impact_body_ >= 0) {
        std::vector<double> contact(impact_contact_.begin(), impact_contact_.end()), velocity;
        for (const auto& v : impact_velocity_) velocity.insert(velocity.end(), v.begin(), v.end());
        state["impact_contact"] = io::Json::array_of(contact);
        state["impact_velocity"] = io::Json::array_of(velocity);
        state["impact_energy"] = io::Json::array_of(impact_energy_);
      }
      solid_.write_checkpoint(writer);
      if (contact_) contact_->write_checkpoint(writer, "contact_");
      writer.commit();
    };

    int total_newton = 0, total_linear = 0;
    Progress progress(time.n_steps, time.end_time, (first_step - 1) * time.step);
    // A step whose Newton fails: the trial state is dropped and the run folder keeps the last
    // committed one beside the failure (its fields unless written already, a checkpoint to
    // --restart from); the caller marks the run failed.
    const auto keep_last_good_state = [&](int last_step) {
      solid_.restore();
      const double last_time = last_step * time.step;
      const bool written =
          last_step % parameters().vtk_interval == 0 && (last_step >= first_step || !restart_);
      if (parameters().write_vtk && !written) write_vtk(output, last_time);
      checkpoint(last_step, last_time);
      output.keep_last_good_state(last_step, last_time);
    };
    for (int step = first_step; step <= time.n_steps; ++step) {
      const double t = step * time.step;
      StepReport report;
      try {
        report = solid_.step(t, time.step, output);
      } catch (const ConvergenceError&) {
        keep_last_good_state(step - 1);
        throw;
      }
      solid_.commit();
      total_newton += report.newton_iterations;
      total_linear += report.linear_iterations;
      record(step, t, report.newton_iterations);
      progress.step(
          step, t,
          fmt::format("newton {} (|R| {:.2e} -> {:.2e}), ksp {}", report.newton_iterations,
                      report.history.front(), report.norm(), report.linear_iterations));
      if (parameters().write_vtk && step % parameters().vtk_interval == 0) write_vtk(output, t);
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
    if (contact_) write_contact_figures(benchmark);
    if (impact_body_ >= 0) write_impacts(benchmark, times);
    benchmark["time_step"] = time.step;
    auto& iterations = output.summary()["iterations"];
    iterations["newton"] = total_newton;
    iterations["linear"] = total_linear;
  }

  /// The impacts of `impacts.body` (find_impacts) into the benchmark: per impact its times,
  /// angles and energy loss, and the largest loss over the impacts.
  void write_impacts(io::Json& benchmark, const std::vector<double>& times) const {
    const auto impacts = find_impacts(times, impact_contact_, impact_velocity_, impact_energy_);
    std::vector<double> incidence, rebound, loss, start;
    double largest = 0;
    for (const auto& impact : impacts) {
      incidence.push_back(impact.incidence_angle);
      rebound.push_back(impact.rebound_angle);
      loss.push_back(impact.energy_loss);
      start.push_back(impact.start_time);
      largest = std::max(largest, impact.energy_loss);
      log::info(
          "impact of '{}' at t = {:g}..{:g} s: incidence {:.3f} deg, rebound {:.3f} deg, energy "
          "{:.6e} -> {:.6e} (loss {:.3f} %)",
          impact_body_name_, impact.start_time, impact.end_time, impact.incidence_angle,
          impact.rebound_angle, impact.energy_before, impact.energy_after,
          100 * impact.energy_loss);
    }
    benchmark["impacts"] = static_cast<std::int64_t>(impacts.size());
    benchmark["impact_times"] = io::Json::array_of(start);
    benchmark["incidence_angles"] = io::Json::array_of(incidence);
    benchmark["rebound_angles"] = io::Json::array_of(rebound);
    benchmark["energy_loss_per_impact"] = io::Json::array_of(loss);
    benchmark["max_energy_loss_per_impact"] = largest;
  }

  contact::ContactParameters contact_parameters_;
  contact::HertzParameters hertz_;
  contact::PatchTestParameters patch_test_;
  std::string impact_body_name_;  ///< `impacts.body` ("" : none)
  int impact_body_ = -1;          ///< its index in the bodies
  // per recorded step: in contact, the body's barycentre velocity, the total energy
  std::vector<char> impact_contact_;
  std::vector<std::array<double, 3>> impact_velocity_;
  std::vector<double> impact_energy_;
  SolidModel solid_;
  std::unique_ptr<contact::ContactHook> contact_;  ///< null without a `contact:` section
  const run::CheckpointReader* restart_ = nullptr;
};

}  // namespace

std::unique_ptr<run::Problem> create_solid_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<SolidProblem>(root, comm);
}

}  // namespace coapt::solid
