/// @file transfer_problem.cpp
/// `problem: transfer`: see transfer_problem.hpp. Stages: setup (load and place the meshes),
/// assemble (the operators, then the check operators with the roles swapped), transfer
/// (T m and optionally the standard variant), errors, output.
///
/// Errors at the constrained slave nodes C (e_i = (T m)_i − f(x_i)):
///   max_error = max_{i∈C} |e_i|,  l2_error = ( Σ_{i∈C} w_i e_i² )^{1/2},  w_i = ∫_S λ_i
/// (the lumped-mass norm over the constrained nodes; w_i ~ h^d, so l2_error is comparable
/// with a continuous L2 norm over the constrained region).
/// Conservation: Σ_i (B m)_i = ∫_Ω m_h because Σ_i ψ_i = 1 on every slave cell; the same
/// integral from the master side is Σ_j m_j ∫_Ω φ_j with ∫_Ω φ_j = c'_j ∫_M φ_j, c' the
/// covered fraction of the swapped transfer (master as slave). Likewise Σ_ij B_ij = |Ω| =
/// Σ_j ∫_Ω φ_j. The two sides clip the pairs in the opposite order and sum them differently,
/// so they agree to round-off only if the intersections neither lose nor double-count volume.

#include "coapt/transfer/transfer_problem.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/mesh/mesh_input.hpp"
#include "coapt/transfer/operators.hpp"

namespace coapt::transfer {
namespace {

using config::Bounds;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A vector key whose length can only be checked once the mesh (and its dimension) is known.
struct VectorKey {
  std::vector<double> value;
  std::string where;  ///< "file:line: path" for messages

  /// The value padded with zeros to `dim` entries when absent (empty), else checked.
  std::vector<double> of_dimension(int dim) const {
    if (value.empty()) return std::vector<double>(static_cast<std::size_t>(dim), 0.0);
    if (static_cast<int>(value.size()) != dim)
      throw InputError(fmt::format("{}: expected {} values (the mesh is {}D), got {}", where, dim,
                                   dim, value.size()));
    return value;
  }
};

VectorKey read_vector(const config::Section& section, std::string_view key,
                      const config::KeyInfo& info) {
  VectorKey v;
  v.value = section.get<std::vector<double>>(key, {}, info);
  v.where = section.located(key);
  return v;
}

/// Rigid motion applied to a mesh after loading: x → R (x − centre) + centre + translation.
struct Placement {
  double rotation = 0;  ///< [rad], right-handed about `axis` (2D: in the plane)
  std::vector<double> axis;
  std::string axis_where;
  VectorKey centre, translation;
};

/// One mesh of the case: where it comes from and where it is put.
struct MeshSource {
  mesh::MeshInput input;
  Placement placement;
};

/// f(x) = value + gradient·x + amplitude·sin(2π wave·x).
struct AnalyticField {
  double value = 0, amplitude = 0;
  VectorKey gradient, wave;
};

struct Parameters {
  MeshSource slave, master;
  AnalyticField field;
  double coverage_threshold = 1.0 - 1e-10;
  bool standard = false;
  bool check = true;
  bool write_vtk = true;
};

MeshSource read_mesh_source(const config::Section& meshes, const std::string& name,
                            const std::string& doc, int extra_level) {
  const config::Section section = meshes.section(name, doc);
  MeshSource source;
  source.input = mesh::MeshInput::read(section, section.case_directory());
  if (extra_level > 0) {
    if (source.input.type == "gmsh")
      meshes.fail("level", fmt::format("the {} mesh is read from a file ({}) and cannot be "
                                       "refined: use level 0, or a .geo file with type: geo",
                                       name, source.input.file));
    if (source.input.level + extra_level > 12)
      meshes.fail("level", fmt::format("the {} mesh would reach level {} (at most 12)", name,
                                       source.input.level + extra_level));
    source.input.level += extra_level;
    for (int& n : source.input.cells) n <<= extra_level;
  }
  const config::Section placement = section.section(
      "placement", "rigid motion after loading: x -> R(x - centre) + centre + translation");
  source.placement.rotation =
      placement.get<double>(
          "rotation", 0.0,
          {"deg", "rotation angle, right-handed about `axis` (2D: in the plane)"}) *
      std::numbers::pi / 180.0;
  source.placement.axis = placement.get<std::vector<double>>(
      "axis", {0.0, 0.0, 1.0}, {"", "rotation axis (3D meshes; any length but zero)"});
  if (source.placement.axis.size() != 3) placement.fail("axis", "expected 3 values");
  if (std::hypot(source.placement.axis[0], source.placement.axis[1], source.placement.axis[2]) ==
      0.0)
    placement.fail("axis", "the rotation axis must not be zero");
  source.placement.centre =
      read_vector(placement, "centre", {"m", "centre of the rotation (default: the origin)"});
  source.placement.translation =
      read_vector(placement, "translation", {"m", "translation after the rotation (default: 0)"});
  return source;
}

Parameters read(const config::Section& root) {
  Parameters p;
  const config::Section meshes = root.section("mesh", "the two meshes of the transfer");
  const int level = meshes.get<int>(
      "level", 0,
      {"", "refinement level added to both meshes' own levels (each level halves the sizes)",
       Bounds::closed(0, 8)});
  p.slave = read_mesh_source(meshes, "slave", "the slave mesh (the fluid side; receives the field)",
                             level);
  p.master = read_mesh_source(meshes, "master",
                              "the master mesh (the solid side; carries the field)", level);
  const config::Section field = root.section(
      "field", "the analytic field f(x) = value + gradient.x + amplitude sin(2 pi wave.x)");
  p.field.value = field.get<double>("value", 0.0, {"", "constant part"});
  p.field.gradient =
      read_vector(field, "gradient", {"1/m", "gradient of the linear part (default: 0)"});
  p.field.amplitude = field.get<double>("amplitude", 0.0, {"", "amplitude of the sine part"});
  p.field.wave = read_vector(field, "wave", {"1/m", "wave vector of the sine part (default: 0)"});
  const config::Section options = root.section("transfer", "the transfer operators");
  p.coverage_threshold = options.get<double>("coverage_threshold", 1.0 - 1e-10,
                                             {"",
                                              "a slave node is constrained when this fraction of "
                                              "its support is covered (default 1 - 1e-10)",
                                              Bounds{0.0, 1.0, true, false}});
  p.standard = options.get<bool>(
      "standard", false, {"", "also apply the standard variant M_S^-1 B_std (CG) and report it"});
  p.check = options.get<bool>(
      "check", true,
      {"", "check the conservation against a transfer with the roles of the meshes swapped"});
  p.write_vtk = root.section("output", "what the run writes")
                    .get<bool>("vtk", true, {"", "write both meshes with their fields as VTK"});
  return p;
}

/// Applies the placement to every local vertex (owned and ghost: the motion is pointwise).
void place(mesh::Mesh& m, const Placement& placement) {
  const int dim = m.dim;
  const std::vector<double> centre = placement.centre.of_dimension(dim);
  const std::vector<double> translation = placement.translation.of_dimension(dim);
  // Rodrigues: R = cos θ I + sin θ [n]× + (1 − cos θ) n nᵀ (2D: n = e_z).
  double n[3] = {0, 0, 1};
  if (dim == 3) {
    const double length = std::hypot(placement.axis[0], placement.axis[1], placement.axis[2]);
    for (int k = 0; k < 3; ++k) n[k] = placement.axis[k] / length;
  }
  const double c = std::cos(placement.rotation), s = std::sin(placement.rotation);
  const double rotation[3][3] = {{c + (1 - c) * n[0] * n[0], (1 - c) * n[0] * n[1] - s * n[2],
                                  (1 - c) * n[0] * n[2] + s * n[1]},
                                 {(1 - c) * n[1] * n[0] + s * n[2], c + (1 - c) * n[1] * n[1],
                                  (1 - c) * n[1] * n[2] - s * n[0]},
                                 {(1 - c) * n[2] * n[0] - s * n[1],
                                  (1 - c) * n[2] * n[1] + s * n[0], c + (1 - c) * n[2] * n[2]}};
  for (int v = 0; v < m.n_vertices(); ++v) {
    double* x = m.coordinates.data() + static_cast<std::size_t>(v) * dim;
    double relative[3] = {0, 0, 0}, moved[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) relative[k] = x[k] - centre[k];
    for (int i = 0; i < dim; ++i)
      for (int k = 0; k < dim; ++k) moved[i] += rotation[i][k] * relative[k];
    for (int k = 0; k < dim; ++k) x[k] = moved[k] + centre[k] + translation[k];
  }
}

/// Largest edge length over the owned cells (all ranks).
double largest_edge(const mesh::Mesh& m) {
  double h = 0;
  for (int c = 0; c < m.n_owned_cells; ++c) {
    const auto vertices = m.cell(c);
    for (std::size_t a = 0; a < vertices.size(); ++a)
      for (std::size_t b = a + 1; b < vertices.size(); ++b) {
        double squared = 0;
        for (int k = 0; k < m.dim; ++k) {
          const double d = m.point(vertices[a])[k] - m.point(vertices[b])[k];
          squared += d * d;
        }
        h = std::max(h, std::sqrt(squared));
      }
  }
  MPI_Allreduce(MPI_IN_PLACE, &h, 1, MPI_DOUBLE, MPI_MAX, m.comm);
  return h;
}

/// ∫_M φ_j per owned vertex (the lumped mass), in the mesh's layout. Collective.
OwnedVec lumped_mass(const mesh::Mesh& m) {
  OwnedVec mass = fem::create_vertex_vector(m, 1);
  fem::assemble_vector(m, 1, mass, [&](int c, double* element) {
    const auto vertices = m.cell(c);
    const int k = static_cast<int>(vertices.size());
    // |cell| from the vertices: |det(x_a − x_0)| / d!
    double e[3][3] = {};
    for (int a = 1; a < k; ++a)
      for (int d = 0; d < m.dim; ++d)
        e[a - 1][d] = m.point(vertices[a])[d] - m.point(vertices[0])[d];
    const double measure = m.dim == 2
                               ? 0.5 * std::fabs(e[0][0] * e[1][1] - e[0][1] * e[1][0])
                               : std::fabs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                                           e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                                           e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
                                     6.0;
    for (int a = 0; a < k; ++a) element[a] = measure / k;
  });
  return mass;
}

double max_over_ranks(double value, MPI_Comm comm) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm);
  return value;
}

class TransferProblem final : public run::Problem {
 public:
  TransferProblem(const config::Section& root, MPI_Comm comm)
      : parameters_(read(root)),
        comm_(comm),
        slave_(mesh::load_mesh(parameters_.slave.input, comm)),
        master_(mesh::load_mesh(parameters_.master.input, comm)) {
    if (slave_.dim != master_.dim)
      throw InputError(
          fmt::format("mesh: the slave mesh ({}) is {}D but the master mesh ({}) is {}D",
                      parameters_.slave.input.describe(), slave_.dim,
                      parameters_.master.input.describe(), master_.dim));
    place(slave_, parameters_.slave.placement);
    place(master_, parameters_.master.placement);
    gradient_ = parameters_.field.gradient.of_dimension(slave_.dim);
    wave_ = parameters_.field.wave.of_dimension(slave_.dim);
  }

  void describe() const override {
    log::info("transfer: slave {}; master {}", parameters_.slave.input.describe(),
              parameters_.master.input.describe());
    log::info(
        "slave: {} cells, {} vertices; master: {} cells, {} vertices; dimension {}, {} "
        "rank(s)",
        slave_.n_global_cells, slave_.n_global_vertices, master_.n_global_cells,
        master_.n_global_vertices, slave_.dim, size_of(comm_));
    std::string gradient, wave;
    for (std::size_t k = 0; k < gradient_.size(); ++k) {
      gradient += fmt::format("{}{:g}", k ? ", " : "", gradient_[k]);
      wave += fmt::format("{}{:g}", k ? ", " : "", wave_[k]);
    }
    log::info("field: f(x) = {:g} + ({})·x + {:g} sin(2 pi ({})·x)", parameters_.field.value,
              gradient, parameters_.field.amplitude, wave);
  }

  void run(run::RunOutput& output) override {
    describe();
    auto& benchmark = output.summary()["benchmark"];

    // Operators (timed inside: search, intersection, assembly).
    TransferOptions options;
    options.coverage_threshold = parameters_.coverage_threshold;
    options.standard = parameters_.standard;
    std::unique_ptr<VariationalTransfer> transfer;
    {
      ScopedTimer timer(output.timers(), "assemble");
      transfer = std::make_unique<VariationalTransfer>(slave_, master_, options);
    }
    const TransferStatistics& statistics = transfer->statistics();
    std::int64_t pairs = statistics.intersecting_pairs;
    MPI_Allreduce(MPI_IN_PLACE, &pairs, 1, MPI_INT64_T, MPI_SUM, comm_);
    const double search_seconds = max_over_ranks(statistics.search_seconds, comm_);
    const double intersection_seconds = max_over_ranks(statistics.intersection_seconds, comm_);
    const double assembly_seconds = max_over_ranks(statistics.assembly_seconds, comm_);
    log::info(
        "operators: {} intersecting pairs, {} constrained slave nodes of {}; search {:.3f} "
        "s, intersection {:.3f} s, assembly {:.3f} s (max over ranks)",
        pairs, transfer->n_constrained(), slave_.n_global_vertices, search_seconds,
        intersection_seconds, assembly_seconds);

    // The field on the master, transferred.
    OwnedVec master_field = transfer->create_master_vector();
    {
      PetscScalar* m = nullptr;
      COAPT_PETSC_CHECK(VecGetArray(master_field, &m));
      for (int v = 0; v < master_.n_owned_vertices; ++v) m[v] = field(master_.point(v));
      COAPT_PETSC_CHECK(VecRestoreArray(master_field, &m));
    }
    OwnedVec transferred = fem::create_vertex_vector(slave_, 1);
    OwnedVec standard = parameters_.standard ? fem::create_vertex_vector(slave_, 1) : OwnedVec();
    COAPT_PETSC_CHECK(VecSet(transferred, 0.0));
    double transfer_seconds = 0, standard_seconds = 0;
    {
      ScopedTimer timer(output.timers(), "transfer");
      const auto start = Clock::now();
      transfer->apply_transfer(master_field, transferred);
      transfer_seconds = max_over_ranks(seconds_since(start), comm_);
      if (parameters_.standard) {
        const auto standard_start = Clock::now();
        transfer->apply_standard_transfer(master_field, standard);
        standard_seconds = max_over_ranks(seconds_since(standard_start), comm_);
      }
    }
    fem::update_ghosts(transferred);
    if (parameters_.standard) fem::update_ghosts(standard);

    // Errors at the constrained nodes.
    OwnedVec marker = fem::create_vertex_vector(slave_, 1);
    OwnedVec weight = lumped_mass(slave_);
    COAPT_PETSC_CHECK(VecSet(marker, 0.0));
    {
      PetscScalar* flag = nullptr;
      COAPT_PETSC_CHECK(VecGetArray(marker, &flag));
      for (PetscInt row : transfer->constrained_rows()) flag[row - slave_.vertex_offset] = 1.0;
      COAPT_PETSC_CHECK(VecRestoreArray(marker, &flag));
    }
    fem::update_ghosts(marker);
    std::vector<double> exact(static_cast<std::size_t>(slave_.n_vertices()));
    for (int v = 0; v < slave_.n_vertices(); ++v) exact[v] = field(slave_.point(v));
    std::vector<double> error(exact.size(), 0.0), standard_error;
    if (parameters_.standard) standard_error.assign(exact.size(), 0.0);
    // sums: l2², standard l2², |f| scale; maxima: error, standard error
    double sums[2] = {0, 0}, maxima[3] = {0, 0, 0};
    {
      fem::LocalValues t(transferred), flag(marker), w(weight);
      std::unique_ptr<fem::LocalValues> t_std;
      if (parameters_.standard) t_std = std::make_unique<fem::LocalValues>(standard);
      for (int v = 0; v < slave_.n_vertices(); ++v) {
        if (flag[v] != 1.0) continue;
        error[v] = t[v] - exact[v];
        if (parameters_.standard) standard_error[v] = (*t_std)[v] - exact[v];
        if (v >= slave_.n_owned_vertices) continue;
        sums[0] += w[v] * error[v] * error[v];
        maxima[0] = std::max(maxima[0], std::fabs(error[v]));
        if (parameters_.standard) {
          sums[1] += w[v] * standard_error[v] * standard_error[v];
          maxima[1] = std::max(maxima[1], std::fabs(standard_error[v]));
        }
        maxima[2] = std::max(maxima[2], std::fabs(exact[v]));
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, comm_);
    MPI_Allreduce(MPI_IN_PLACE, maxima, 3, MPI_DOUBLE, MPI_MAX, comm_);
    const double l2_error = std::sqrt(sums[0]), max_error = maxima[0];
    log::info(
        "T = D^-1 B at the {} constrained nodes: max error {:.6e}, L2 error {:.6e} (max "
        "|f| there {:.4e})",
        transfer->n_constrained(), max_error, l2_error, maxima[2]);
    if (parameters_.standard)
      log::info("standard variant at the same nodes: max error {:.6e}, L2 error {:.6e}", maxima[1],
                std::sqrt(sums[1]));

    // Conservation: the slave side (B) against the master side (the swapped transfer).
    double slave_side[2] = {0, 0};  // Σ_i (B m)_i, Σ_ij B_ij
    {
      OwnedVec product = transfer->create_slave_vector(), ones = transfer->create_master_vector();
      COAPT_PETSC_CHECK(MatMult(transfer->coupling(), master_field, product));
      COAPT_PETSC_CHECK(VecSum(product, &slave_side[0]));
      COAPT_PETSC_CHECK(VecSet(ones, 1.0));
      COAPT_PETSC_CHECK(MatMult(transfer->coupling(), ones, product));
      COAPT_PETSC_CHECK(VecSum(product, &slave_side[1]));
    }
    benchmark["slave_vertices"] = static_cast<std::int64_t>(slave_.n_global_vertices);
    benchmark["master_vertices"] = static_cast<std::int64_t>(master_.n_global_vertices);
    benchmark["slave_h"] = largest_edge(slave_);
    benchmark["master_h"] = largest_edge(master_);
    benchmark["intersecting_pairs"] = pairs;
    benchmark["constrained_nodes"] = static_cast<std::int64_t>(transfer->n_constrained());
    benchmark["max_error"] = max_error;
    benchmark["l2_error"] = l2_error;
    benchmark["field_max"] = maxima[2];
    if (parameters_.standard) {
      benchmark["standard_max_error"] = maxima[1];
      benchmark["standard_l2_error"] = std::sqrt(sums[1]);
    }
    benchmark["integral_slave_side"] = slave_side[0];
    benchmark["overlap_volume_slave_side"] = slave_side[1];
    benchmark["search_seconds"] = search_seconds;
    benchmark["intersection_seconds"] = intersection_seconds;
    benchmark["assembly_seconds"] = assembly_seconds;
    benchmark["transfer_seconds"] = transfer_seconds;
    if (parameters_.standard) benchmark["standard_transfer_seconds"] = standard_seconds;
    if (parameters_.check) {
      ScopedTimer timer(output.timers(), "check");
      const auto start = Clock::now();
      VariationalTransfer swapped(master_, slave_);
      OwnedVec covered_mass = lumped_mass(master_);
      COAPT_PETSC_CHECK(VecPointwiseMult(covered_mass, covered_mass, swapped.coverage()));
      double master_side[2] = {0, 0};  // Σ_j m_j ∫_Ω φ_j, Σ_j ∫_Ω φ_j
      COAPT_PETSC_CHECK(VecDot(master_field, covered_mass, &master_side[0]));
      COAPT_PETSC_CHECK(VecSum(covered_mass, &master_side[1]));
      double field_scale = 0;
      COAPT_PETSC_CHECK(VecNorm(master_field, NORM_INFINITY, &field_scale));
      const double conservation_error =
          std::fabs(slave_side[0] - master_side[0]) /
          std::max(std::fabs(master_side[1]) * field_scale, std::numeric_limits<double>::min());
      const double volume_error =
          std::fabs(slave_side[1] - master_side[1]) / std::fabs(master_side[1]);
      log::info(
          "conservation: sum B m = {:.15e}, master side {:.15e} (difference {:.2e} "
          "relative to |overlap| max|m|)",
          slave_side[0], master_side[0], conservation_error);
      log::info("overlap: sum B_ij = {:.15e}, master side {:.15e} (relative difference {:.2e})",
                slave_side[1], master_side[1], volume_error);
      benchmark["integral_master_side"] = master_side[0];
      benchmark["overlap_volume_master_side"] = master_side[1];
      benchmark["conservation_error"] = conservation_error;
      benchmark["overlap_volume_error"] = volume_error;
      benchmark["check_seconds"] = max_over_ranks(seconds_since(start), comm_);
    }
    output.series().add("time", 0.0);
    output.series().add("max_error", max_error);
    output.series().add("l2_error", l2_error);
    output.series().end_row();

    if (parameters_.write_vtk) {
      ScopedTimer timer(output.timers(), "output");
      std::vector<double> master_values(static_cast<std::size_t>(master_.n_vertices()));
      for (int v = 0; v < master_.n_vertices(); ++v) master_values[v] = field(master_.point(v));
      const std::vector<io::Field> master_fields = {
          {"field", 1, io::Field::Location::vertex, master_values}};
      output.vtk("master").write(master_, 0.0, master_fields);
      fem::LocalValues t(transferred), flag(marker);
      std::vector<io::Field> slave_fields = {
          {"transferred", 1, io::Field::Location::vertex, t.values()},
          {"exact", 1, io::Field::Location::vertex, exact},
          {"error", 1, io::Field::Location::vertex, error},
          {"constrained", 1, io::Field::Location::vertex, flag.values()},
      };
      std::unique_ptr<fem::LocalValues> t_std;
      if (parameters_.standard) {
        t_std = std::make_unique<fem::LocalValues>(standard);
        slave_fields.push_back({"standard", 1, io::Field::Location::vertex, t_std->values()});
        slave_fields.push_back({"standard_error", 1, io::Field::Location::vertex, standard_error});
      }
      output.vtk("slave").write(slave_, 0.0, slave_fields);
    }
  }

 private:
  double field(std::span<const double> x) const {
    double linear = parameters_.field.value, phase = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      linear += gradient_[k] * x[k];
      phase += wave_[k] * x[k];
    }
    return linear + parameters_.field.amplitude * std::sin(2.0 * std::numbers::pi * phase);
  }

  const Parameters parameters_;
  MPI_Comm comm_;
  mesh::Mesh slave_, master_;
  std::vector<double> gradient_, wave_;
};

}  // namespace

std::unique_ptr<run::Problem> create_transfer_problem(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<TransferProblem>(root, comm);
}

}  // namespace coapt::transfer
