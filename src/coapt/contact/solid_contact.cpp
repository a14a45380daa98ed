// The contact Newton hook of the solid, its output, and the Hertz comparison.
#include "coapt/contact/solid_contact.hpp"

#include <fmt/format.h>
#include <mpi.h>
#include <petscsys.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <span>

#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/assembly.hpp"

namespace coapt::contact {

using config::Bounds;

HertzParameters HertzParameters::read(const config::Section& root) {
  HertzParameters h;
  if (!root.has("hertz")) return h;
  const auto section =
      root.section("hertz", "analytic Hertz reference for the benchmark (Johnson 1985)");
  h.enabled = true;
  h.sphere =
      section.choice("geometry", "cylinder", {"cylinder", "sphere"},
                     {"", "cylinder: 2D line contact, sphere: 3D point contact"}) == "sphere";
  h.radius = section.require<double>("radius", {"m", "radius R of the body", Bounds::positive()});
  h.load = section.require<double>(
      "load", {"N/m or N", "load P on the whole body (per unit length for a cylinder)",
               Bounds::positive()});
  h.young_modulus = section.require<double>(
      "young_modulus",
      {"Pa", "Young's modulus of the body (the flat is rigid)", Bounds::positive()});
  h.poisson_ratio = section.require<double>(
      "poisson_ratio", {"", "Poisson's ratio of the body", Bounds::open(-1.0, 0.5)});
  return h;
}

PatchTestParameters PatchTestParameters::read(const config::Section& root) {
  PatchTestParameters p;
  if (!root.has("patch_test")) return p;
  const auto section = root.section("patch_test", "contact patch test reference");
  p.enabled = true;
  p.force = section.require<double>(
      "force",
      {"N/m or N", "the total normal load the contact surface must transmit", Bounds::positive()});
  return p;
}

double pressure_error(const ContactConstraints& constraints, double force) {
  const double pressure = force / constraints.status().contact_measure;
  double error = 0.0;
  for (const auto& pair : constraints.pairs())
    for (int j = 0; j < pair.slave.n_nodes(); ++j)
      if (pair.active[j]) error = std::max(error, std::abs(pair.pressure[j] - pressure) / pressure);
  return error;
}

double HertzParameters::max_pressure() const {
  const double E = effective_modulus();
  if (!sphere) return std::sqrt(load * E / (M_PI * radius));
  return std::cbrt(6.0 * load * E * E / (M_PI * M_PI * M_PI * radius * radius));
}

double HertzParameters::contact_size() const {
  const double E = effective_modulus();
  if (!sphere) return std::sqrt(4.0 * load * radius / (M_PI * E));
  return std::cbrt(3.0 * load * radius / (4.0 * E));
}

std::vector<double> nominal_pressures(const PairState& pair) {
  const auto reference_area = nodal_measures(pair.slave, pair.slave.reference);
  std::vector<double> nominal(reference_area.size(), 0.0);
  for (std::size_t j = 0; j < nominal.size(); ++j)
    if (pair.pressure[j] != 0.0 && reference_area[j] > 0.0)
      nominal[j] = pair.pressure[j] * pair.mortar.dual_mass[j] / reference_area[j];
  return nominal;
}

HertzMeasurement measure_hertz(const ContactConstraints& constraints, bool sphere) {
  HertzMeasurement m;
  // Least squares of p² = A − B r² over the active nodes: b = √(A/B), p₀ = √A.
  double s1 = 0, sx = 0, sxx = 0, sy = 0, sxy = 0;
  for (const auto& pair : constraints.pairs()) {
    const int dim = pair.slave.dim;
    const auto nominal = nominal_pressures(pair);
    for (int j = 0; j < pair.slave.n_nodes(); ++j) {
      if (!pair.active[j]) continue;
      const double* x = pair.slave.reference.data() + static_cast<std::size_t>(j) * dim;
      const double r = sphere ? std::hypot(x[0], x[1]) : std::abs(x[0]);
      const double p = pair.pressure[j];
      ++m.active_nodes;
      m.max_pressure = std::max(m.max_pressure, p);
      m.max_nominal_pressure =
          std::max(m.max_nominal_pressure, nominal[static_cast<std::size_t>(j)]);
      m.outermost_active = std::max(m.outermost_active, r);
      const double X = r * r, Y = p * p;
      s1 += 1;
      sx += X;
      sxx += X * X;
      sy += Y;
      sxy += X * Y;
    }
  }
  const double det = s1 * sxx - sx * sx;
  if (m.active_nodes >= 2 && det > 0) {
    const double A = (sxx * sy - sx * sxy) / det;
    const double slope = (s1 * sxy - sx * sy) / det;  // −B
    if (A > 0 && slope < 0) {
      m.fitted_pressure = std::sqrt(A);
      m.contact_size = std::sqrt(-A / slope);
    }
  }
  return m;
}

ContactParameters read_solid_contact(const config::Section& root) {
  auto parameters = ContactParameters::read(root);
  if (parameters.enabled()) {
    PetscBool ksp = PETSC_FALSE, pc = PETSC_FALSE, factor = PETSC_FALSE;
    COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, "solid_", "-ksp_type", &ksp));
    COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, "solid_", "-pc_type", &pc));
    COAPT_PETSC_CHECK(
        PetscOptionsHasName(nullptr, "solid_", "-pc_factor_mat_solver_type", &factor));
    if (!ksp && !pc) {
      COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, "-solid_ksp_type", "preonly"));
      COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, "-solid_pc_type", "lu"));
      if (!factor)
        COAPT_PETSC_CHECK(
            PetscOptionsSetValue(nullptr, "-solid_pc_factor_mat_solver_type", "mumps"));
    }
  }
  return parameters;
}

namespace {

using Point = std::array<double, 3>;

Point point_of(std::span<const double> x, int dim, int node) {
  Point p{};
  for (int i = 0; i < dim; ++i) p[i] = x[static_cast<std::size_t>(node) * dim + i];
  return p;
}

double dot(const Point& a, const Point& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point minus(const Point& a, const Point& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

/// Distance from p to the segment [a, b].
double segment_distance(const Point& p, const Point& a, const Point& b) {
  const Point ab = minus(b, a), ap = minus(p, a);
  const double length2 = dot(ab, ab);
  const double s = length2 > 0 ? std::clamp(dot(ap, ab) / length2, 0.0, 1.0) : 0.0;
  const Point d{ap[0] - s * ab[0], ap[1] - s * ab[1], ap[2] - s * ab[2]};
  return std::sqrt(dot(d, d));
}

/// Distance from p to the triangle (a, b, c): to its plane where p projects inside it, else
/// to the nearest edge.
double triangle_distance(const Point& p, const Point& a, const Point& b, const Point& c) {
  const Point ab = minus(b, a), ac = minus(c, a), ap = minus(p, a);
  const Point n{ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                ab[0] * ac[1] - ab[1] * ac[0]};
  const double area2 = dot(n, n);
  if (area2 > 0) {
    // barycentric coordinates of the projection of p
    const double d00 = dot(ab, ab), d01 = dot(ab, ac), d11 = dot(ac, ac);
    const double d20 = dot(ap, ab), d21 = dot(ap, ac);
    const double denominator = d00 * d11 - d01 * d01;
    const double v = (d11 * d20 - d01 * d21) / denominator;
    const double w = (d00 * d21 - d01 * d20) / denominator;
    if (v >= 0 && w >= 0 && v + w <= 1) return std::abs(dot(ap, n)) / std::sqrt(area2);
  }
  return std::min(
      {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

}  // namespace

double surface_distance(const PairState& pair) {
  const int dim = pair.slave.dim;
  double distance = std::numeric_limits<double>::infinity();
  for (int j = 0; j < pair.slave.n_nodes(); ++j) {
    const Point p = point_of(pair.slave_x, dim, j);
    for (int f = 0; f < pair.master.n_facets(); ++f) {
      const auto nodes = pair.master.facet(f);
      const Point a = point_of(pair.master_x, dim, nodes[0]);
      const Point b = point_of(pair.master_x, dim, nodes[1]);
      distance = std::min(
          distance, dim == 2 ? segment_distance(p, a, b)
                             : triangle_distance(p, a, b, point_of(pair.master_x, dim, nodes[2])));
    }
  }
  return distance;
}

ContactHook::ContactHook(const ContactParameters& parameters, const solid::SolidModel& solid)
    : parameters_(parameters),
      mesh_(solid.mesh()),
      constraints_(parameters, solid.mesh(), solid.dirichlet_dofs(), solid.displacement()) {}

void ContactHook::write_checkpoint(run::CheckpointWriter& writer, const std::string& prefix) const {
  auto marker = fem::create_vertex_vector(mesh_, mesh_.dim);
  for (std::size_t p = 0; p < constraints_.pairs().size(); ++p) {
    constraints_.active_marker(p, marker);
    writer.add_vertex_field(fmt::format("{}active{}", prefix, p), mesh_, marker, mesh_.dim);
  }
  auto& state = writer.state()[prefix + "contact"];
  state["pairs"] = static_cast<std::int64_t>(constraints_.pairs().size());
  state["complementarity_constant"] = constraints_.complementarity_constant();
}

void ContactHook::read_checkpoint(const run::CheckpointReader& reader, const std::string& prefix) {
  const auto& checkpoint = reader.state();
  const auto key = prefix + "contact";
  if (!checkpoint.contains(key) || checkpoint.at(key).at("pairs").as_int() !=
                                       static_cast<std::int64_t>(constraints_.pairs().size()))
    throw InputError(fmt::format("{}: the checkpoint's contact state ({}) is not of {} pair(s)",
                                 reader.directory().string(), key, constraints_.pairs().size()));
  auto marker = fem::create_vertex_vector(mesh_, mesh_.dim);
  for (std::size_t p = 0; p < constraints_.pairs().size(); ++p) {
    reader.read_vertex_field(fmt::format("{}active{}", prefix, p), mesh_, marker, mesh_.dim);
    constraints_.restore_active(p, marker);
  }
  constraints_.set_complementarity_constant(
      checkpoint.at(key).at("complementarity_constant").as_double());
}

void ContactHook::begin_step(Vec u) {
  (void)u;
  changing_iterations_ = 0;
  changed_nodes_ = 0;
}

void ContactHook::add_residual(Vec u, Vec residual) {
  const double start = MPI_Wtime();
  constraints_.update(u, residual);
  seconds_ += MPI_Wtime() - start;
}

Mat ContactHook::linear_system(Vec u, Mat K, Vec rhs) {
  (void)u;
  const double start = MPI_Wtime();
  Mat system = constraints_.transform(K, rhs);
  seconds_ += MPI_Wtime() - start;
  return system;
}

bool ContactHook::accept(Vec u) {
  (void)u;
  const auto& status = constraints_.status();
  if (status.changes == 0) return true;
  ++changing_iterations_;
  changed_nodes_ += status.changes;
  log::debug("contact: {} node(s) changed the active set ({} active): {}", status.changes,
             status.active, status.changed_nodes);
  if (changing_iterations_ > parameters_.max_active_set_changes)
    throw ConvergenceError(fmt::format(
        "contact: the active set still changes after {} Newton iterations ({} of {} nodes "
        "active, {} changing): cycling; try a larger complementarity_constant or smaller "
        "load steps",
        changing_iterations_ - 1, status.active, status.constrained, status.changes));
  return false;
}

void ContactHook::project_predictor(Vec u, Vec increment, Vec lumped_mass) {
  const double start = MPI_Wtime();
  const int clipped = constraints_.project_predictor(u, increment, lumped_mass);
  seconds_ += MPI_Wtime() - start;
  if (clipped > 0) log::debug("contact: the predictor was clipped at {} slave node(s)", clipped);
}

std::vector<io::Field> ContactHook::fields() {
  constraints_.vertex_fields(pressure_, gap_, active_);
  return {{"contact_pressure", 1, io::Field::Location::vertex, pressure_},
          {"contact_gap", 1, io::Field::Location::vertex, gap_},
          {"contact_active", 1, io::Field::Location::vertex, active_}};
}

void ContactHook::add_series(run::RunOutput& output, const std::string& suffix) const {
  const auto& s = constraints_.status();
  auto& series = output.series();
  series.add("contact_active_nodes" + suffix, s.active);
  series.add("contact_max_pressure" + suffix, s.max_pressure);
  series.add("contact_total_force" + suffix, s.total_force);
  series.add("contact_max_penetration" + suffix, s.max_penetration);
  series.add("contact_min_active_pressure" + suffix, s.min_active_pressure);
  series.add("contact_max_open_pressure" + suffix, s.max_open_pressure);
  series.add("contact_max_complementarity" + suffix, s.max_complementarity);
  series.add("contact_active_set_changes" + suffix, changing_iterations_);
  const int dim = constraints_.pairs().empty() ? 0 : constraints_.pairs().front().slave.dim;
  for (int i = 0; i < dim; ++i)
    series.add(fmt::format("contact_force_{}{}", "xyz"[i], suffix),
               s.force_vector[static_cast<std::size_t>(i)]);
}

void ContactHook::write_nodes(const std::filesystem::path& file, MPI_Comm comm) const {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return;
  std::ofstream out(file);
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
  const int dim = constraints_.pairs().empty() ? 0 : constraints_.pairs().front().slave.dim;
  out << "pair,x,y" << (dim == 3 ? ",z" : "")
      << ",pressure,gap,active,constrained,nominal_pressure\n";
  for (std::size_t p = 0; p < constraints_.pairs().size(); ++p) {
    const auto& pair = constraints_.pairs()[p];
    const auto nominal = nominal_pressures(pair);
    for (int j = 0; j < pair.slave.n_nodes(); ++j) {
      out << p;
      for (int i = 0; i < dim; ++i)
        out << fmt::format(",{:.17g}", pair.slave.reference[static_cast<std::size_t>(j) * dim + i]);
      out << fmt::format(",{:.17g},{:.17g},{},{},{:.17g}\n", pair.pressure[j], pair.mortar.gap(j),
                         int(pair.active[j]), int(pair.mortar.constrained(j)),
                         nominal[static_cast<std::size_t>(j)]);
    }
  }
}

void ContactHook::log_status(const std::string& label) const {
  const auto& s = constraints_.status();
  log::info(
      "{}: contact {} of {} nodes active, pressure in [{:.6e}, {:.6e}] Pa, force {:.6e}, max "
      "penetration {:.3e} m, max |p g| {:.3e}, c = {:.3e} Pa/m",
      label, s.active, s.constrained, s.min_active_pressure, s.max_pressure, s.total_force,
      s.max_penetration, s.max_complementarity, s.complementarity_constant);
}

}  // namespace coapt::contact
