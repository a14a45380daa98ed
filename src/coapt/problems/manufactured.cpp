#include "coapt/problems/manufactured.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <numbers>

#include "coapt/core/context.hpp"
#include "coapt/core/log.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/kernels.hpp"
#include "coapt/fem/linear_solver.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fem/quadrature.hpp"
#include "coapt/mesh/mesh_input.hpp"

namespace coapt::problems {
namespace {

using config::Bounds;
using Vector3 = Eigen::Vector3d;
constexpr double pi = std::numbers::pi;

// The exact solutions are sums of plane waves sin(π w_k·x) (cos for the Poisson's second
// term), so f follows in closed form for any dimension:
//   Poisson:    u = sin(π w0·x) + cos(π w1·x),  f = −Δu = π²|w0|² sin(π w0·x) + π²|w1|² cos(π
//   w1·x); elasticity: u_i = sin(π w_i·x),  −div σ = −μ Δu − (λ+μ) ∇(div u), so
//               f_i = μ π² |w_i|² sin(π w_i·x) + (λ+μ) π² Σ_k w_kk w_ki sin(π w_k·x).
const std::array<Vector3, 3> kWaves = {Vector3(1.0, 0.5, 0.3), Vector3(0.4, 1.2, 0.2),
                                       Vector3(0.3, 0.6, 0.9)};

template <int Dim>
double wave_phase(int k, const Eigen::Matrix<double, Dim, 1>& x) {
  return pi * kWaves[k].head<Dim>().dot(x);
}

/// The manufactured solution, its gradient and source for one equation.
struct PoissonSolution {
  template <int Dim>
  static Eigen::Matrix<double, 1, 1> value(const Eigen::Matrix<double, Dim, 1>& x) {
    return Eigen::Matrix<double, 1, 1>(std::sin(wave_phase<Dim>(0, x)) +
                                       std::cos(wave_phase<Dim>(1, x)));
  }
  template <int Dim>
  static Eigen::Matrix<double, 1, Dim> gradient(const Eigen::Matrix<double, Dim, 1>& x) {
    return (pi * std::cos(wave_phase<Dim>(0, x)) * kWaves[0].head<Dim>() -
            pi * std::sin(wave_phase<Dim>(1, x)) * kWaves[1].head<Dim>())
        .transpose();
  }
  template <int Dim>
  static Eigen::Matrix<double, 1, 1> source(const Eigen::Matrix<double, Dim, 1>& x, double,
                                            double) {
    const double w0 = kWaves[0].head<Dim>().squaredNorm(), w1 = kWaves[1].head<Dim>().squaredNorm();
    return Eigen::Matrix<double, 1, 1>(
        pi * pi * (w0 * std::sin(wave_phase<Dim>(0, x)) + w1 * std::cos(wave_phase<Dim>(1, x))));
  }
};

struct ElasticitySolution {
  template <int Dim>
  static Eigen::Matrix<double, Dim, 1> value(const Eigen::Matrix<double, Dim, 1>& x) {
    Eigen::Matrix<double, Dim, 1> u;
    for (int i = 0; i < Dim; ++i) u(i) = std::sin(wave_phase<Dim>(i, x));
    return u;
  }
  template <int Dim>
  static Eigen::Matrix<double, Dim, Dim> gradient(const Eigen::Matrix<double, Dim, 1>& x) {
    Eigen::Matrix<double, Dim, Dim> g;
    for (int i = 0; i < Dim; ++i)
      g.row(i) = pi * std::cos(wave_phase<Dim>(i, x)) * kWaves[i].head<Dim>().transpose();
    return g;
  }
  template <int Dim>
  static Eigen::Matrix<double, Dim, 1> source(const Eigen::Matrix<double, Dim, 1>& x, double lambda,
                                              double mu) {
    Eigen::Matrix<double, Dim, 1> f;
    for (int i = 0; i < Dim; ++i) {
      double grad_div = 0;
      for (int k = 0; k < Dim; ++k)
        grad_div += kWaves[k](k) * kWaves[k](i) * std::sin(wave_phase<Dim>(k, x));
      f(i) = pi * pi *
             (mu * kWaves[i].head<Dim>().squaredNorm() * std::sin(wave_phase<Dim>(i, x)) +
              (lambda + mu) * grad_div);
    }
    return f;
  }
};

struct Parameters {
  mesh::MeshInput mesh;
  double lambda = 0;  ///< Lamé λ [Pa] (elasticity)
  double mu = 0;      ///< shear modulus [Pa] (elasticity)
  int quadrature_degree = 4;
  bool write_vtk = true;
  std::vector<std::string> dirichlet;  ///< boundary groups with u = exact (empty: all)
  std::string dirichlet_where;         ///< where the key stands, for messages
};

/// The Poisson (n_components = 1) or elasticity (n_components = dim) verification problem.
template <class Solution>
class Manufactured final : public run::Problem {
 public:
  Manufactured(std::string name, const config::Section& root, MPI_Comm comm, bool elastic)
      : name_(std::move(name)),
        parameters_(read(root, elastic)),
        comm_(comm),
        mesh_(mesh::load_mesh(parameters_.mesh, comm, &quality_)),
        n_components_(elastic ? mesh_.dim : 1) {
    for (const auto& name : parameters_.dirichlet) {
      const auto* group = mesh_.find_group(name);
      if (!group || group->dim != mesh_.dim - 1)
        throw InputError(fmt::format("{}: dirichlet: {}: no boundary group '{}' in the mesh ({})",
                                     parameters_.dirichlet_where, mesh_.source, name,
                                     boundary_group_names()));
      dirichlet_tags_.push_back(group->tag);
    }
    if (parameters_.dirichlet.empty())
      for (const auto& group : mesh_.groups)
        if (group.dim == mesh_.dim - 1) dirichlet_tags_.push_back(group.tag);
    if (dirichlet_tags_.empty())
      throw InputError(fmt::format(
          "{}: the mesh has no tagged boundary for the Dirichlet condition", mesh_.source));
  }

  void describe() const override {
    log::info("{}: manufactured solution on {}", name_, parameters_.mesh.describe());
    log::info("mesh: {} cells, {} vertices, dimension {}, {} rank(s)", mesh_.n_global_cells,
              mesh_.n_global_vertices, mesh_.dim, size_of(comm_));
    log::info("cell measure in [{:.3e}, {:.3e}], shape quality in [{:.3f}, {:.3f}]",
              quality_.min_measure, quality_.max_measure, quality_.min_shape, quality_.max_shape);
    if (n_components_ > 1)
      log::info("material: lambda = {:g} Pa, mu = {:g} Pa", parameters_.lambda, parameters_.mu);
  }

  void run(run::RunOutput& output) override {
    describe();
    if (mesh_.dim == 2)
      solve<2>(output);
    else
      solve<3>(output);
  }

 private:
  static Parameters read(const config::Section& root, bool elastic) {
    Parameters p;
    p.mesh = mesh::MeshInput::read(root.section("mesh", "the mesh"), root.case_directory());
    if (elastic) {
      auto material = root.section("material", "linear elastic material");
      const double young = material.get<double>("young_modulus", 1.0,
                                                {"Pa", "Young's modulus E", Bounds::positive()});
      const double poisson = material.get<double>("poisson_ratio", 0.3,
                                                  {"", "Poisson's ratio", Bounds::open(-1.0, 0.5)});
      p.lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
      p.mu = young / (2 * (1 + poisson));
    }
    auto output = root.section("output", "what the run writes");
    p.write_vtk = output.get<bool>("vtk", true, {"", "write the solution and its error as VTK"});
    p.dirichlet = root.get<std::vector<std::string>>(
        "dirichlet", {},
        {"", "boundary groups where u = the exact solution (empty: every boundary group)"});
    p.dirichlet_where = root.where("dirichlet");
    p.quadrature_degree =
        root.get<int>("quadrature_degree", 4,
                      {"", "degree of the rule for f and the errors", Bounds::closed(2, 10)});
    return p;
  }

  template <int Dim>
  Eigen::Matrix<double, Dim + 1, Dim> cell_vertices(int c) const {
    Eigen::Matrix<double, Dim + 1, Dim> x;
    const auto vertices = mesh_.cell(c);
    for (int a = 0; a <= Dim; ++a)
      for (int d = 0; d < Dim; ++d) x(a, d) = mesh_.point(vertices[a])[d];
    return x;
  }

  template <int Dim>
  void solve(run::RunOutput& output) {
    const int n = n_components_;
    constexpr int k = Dim + 1;
    const auto& rule = fem::simplex_quadrature(Dim, parameters_.quadrature_degree);
    const double lambda = parameters_.lambda, mu = parameters_.mu;

    fem::P1Matrix matrix(mesh_, n);
    auto rhs = fem::create_vertex_vector(mesh_, n);
    auto solution = fem::create_vertex_vector(mesh_, n);
    {
      ScopedTimer timer(output.timers(), "assemble");
      matrix.assemble([&](int c, double* element) {
        const double* points[k];
        for (int a = 0; a < k; ++a) points[a] = mesh_.point(mesh_.cell(c)[a]).data();
        if (n == 1)
          fem::element_laplacian<Dim>(points, element);
        else
          fem::element_elasticity<Dim>(points, lambda, mu, element);
      });
      fem::assemble_vector(mesh_, n, rhs, [&](int c, double* element) {
        const auto x = cell_vertices<Dim>(c);
        const auto geometry = fem::p1_geometry<Dim>(x);
        const auto points = fem::quadrature_points<Dim>(x, rule);
        Eigen::MatrixXd f(rule.size(), n);
        for (int q = 0; q < rule.size(); ++q)
          f.row(q) =
              Solution::template source<Dim>(points.row(q).transpose(), lambda, mu).transpose();
        const auto load = fem::element_load<Dim>(geometry, rule, f);
        for (int a = 0; a < k; ++a)
          for (int i = 0; i < n; ++i) element[a * n + i] = load(a, i);
      });
    }
    // Dirichlet data on every tagged boundary facet: the exact solution at the vertices.
    std::vector<PetscInt> dofs;
    for (int tag : dirichlet_tags_) {
      const auto tagged = fem::boundary_dofs(mesh_, n, tag);
      dofs.insert(dofs.end(), tagged.begin(), tagged.end());
    }
    std::sort(dofs.begin(), dofs.end());
    dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
    auto boundary_values = fem::create_vertex_vector(mesh_, n);
    for (int v = 0; v < mesh_.n_owned_vertices; ++v) {
      Eigen::Matrix<double, Dim, 1> x;
      for (int d = 0; d < Dim; ++d) x(d) = mesh_.point(v)[d];
      const auto u = Solution::template value<Dim>(x);
      for (int i = 0; i < n; ++i) {
        const PetscInt dof = mesh_.global_vertex[v] * n + i;
        COAPT_PETSC_CHECK(VecSetValue(boundary_values, dof, u(i), INSERT_VALUES));
      }
    }
    COAPT_PETSC_CHECK(VecAssemblyBegin(boundary_values));
    COAPT_PETSC_CHECK(VecAssemblyEnd(boundary_values));
    fem::apply_dirichlet(matrix.mat(), rhs, dofs, boundary_values);

    fem::LinearSolver solver(comm_, name_ + "_",
                             {n == 1 ? "cg" : "cg", "gamg", 1e-12, 1e-50, 2000});
    if (n > 1) fem::set_rigid_body_modes(mesh_, matrix.mat());
    solver.set_operator(matrix.mat());
    fem::SolveStats stats;
    {
      ScopedTimer timer(output.timers(), "solve");
      stats = solver.solve(rhs, solution);
    }
    fem::update_ghosts(solution);
    log::info("solver {}: {} iterations, {}, residual {:.3e}", solver.describe(), stats.iterations,
              stats.reason, stats.residual_norm);

    // Errors over the owned cells: ‖u_h − u‖_L2 and |u_h − u|_H1 with a degree-q rule.
    double l2 = 0, h1 = 0, h_max = 0;
    std::vector<double> error_field(static_cast<std::size_t>(mesh_.n_owned_cells), 0.0);
    {
      fem::LocalValues u_h(solution);
      for (int c = 0; c < mesh_.n_owned_cells; ++c) {
        const auto x = cell_vertices<Dim>(c);
        const auto geometry = fem::p1_geometry<Dim>(x);
        Eigen::Matrix<double, k, Eigen::Dynamic> nodal(k, n);
        for (int a = 0; a < k; ++a)
          for (int i = 0; i < n; ++i)
            nodal(a, i) = u_h[static_cast<std::size_t>(mesh_.cell(c)[a]) * n + i];
        const Eigen::MatrixXd gradient_h = nodal.transpose() * geometry.gradients;  // n × Dim
        double cell_l2 = 0, cell_h1 = 0;
        for (int q = 0; q < rule.size(); ++q) {
          const Eigen::Map<const Eigen::Matrix<double, Dim, 1>> xi(rule.point(q));
          const auto lambda_q = fem::p1_values<Dim>(xi);
          const Eigen::Matrix<double, Dim, 1> point = fem::map_to_physical<Dim>(x, xi);
          const Eigen::VectorXd difference =
              nodal.transpose() * lambda_q - Eigen::VectorXd(Solution::template value<Dim>(point));
          const Eigen::MatrixXd gradient_difference =
              gradient_h - Eigen::MatrixXd(Solution::template gradient<Dim>(point));
          const double weight = rule.weights[q] * fem::detail::factorial(Dim) * geometry.measure;
          cell_l2 += weight * difference.squaredNorm();
          cell_h1 += weight * gradient_difference.squaredNorm();
        }
        l2 += cell_l2;
        h1 += cell_h1;
        error_field[c] = std::sqrt(cell_l2 / geometry.measure);
        for (int a = 0; a < k; ++a)
          for (int b = a + 1; b < k; ++b) h_max = std::max(h_max, (x.row(a) - x.row(b)).norm());
      }
    }
    double sums[2] = {l2, h1};
    MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, comm_);
    MPI_Allreduce(MPI_IN_PLACE, &h_max, 1, MPI_DOUBLE, MPI_MAX, comm_);
    const double l2_error = std::sqrt(sums[0]), h1_error = std::sqrt(sums[1]);
    log::info("h = {:.4e} m: L2 error {:.6e}, H1 seminorm error {:.6e}", h_max, l2_error, h1_error);

    auto& benchmark = output.summary()["benchmark"];
    benchmark["l2_error"] = l2_error;
    benchmark["h1_error"] = h1_error;
    benchmark["h"] = h_max;
    benchmark["cells"] = static_cast<std::int64_t>(mesh_.n_global_cells);
    benchmark["vertices"] = static_cast<std::int64_t>(mesh_.n_global_vertices);
    auto& iterations = output.summary()["iterations"];
    iterations["linear"] = stats.iterations;
    output.series().add("time", 0.0);
    output.series().add("l2_error", l2_error);
    output.series().add("h1_error", h1_error);
    output.series().end_row();

    if (parameters_.write_vtk) {
      ScopedTimer timer(output.timers(), "output");
      fem::LocalValues u_h(solution);
      std::vector<double> exact(static_cast<std::size_t>(mesh_.n_vertices()) * n);
      for (int v = 0; v < mesh_.n_vertices(); ++v) {
        Eigen::Matrix<double, Dim, 1> x;
        for (int d = 0; d < Dim; ++d) x(d) = mesh_.point(v)[d];
        const auto u = Solution::template value<Dim>(x);
        for (int i = 0; i < n; ++i) exact[static_cast<std::size_t>(v) * n + i] = u(i);
      }
      const std::vector<io::Field> fields = {
          {"u", n, io::Field::Location::vertex, u_h.values()},
          {"u_exact", n, io::Field::Location::vertex, exact},
          {"l2_error_density", 1, io::Field::Location::cell, error_field},
      };
      output.vtk("solution").write(mesh_, 0.0, fields);
    }
  }

  std::string boundary_group_names() const {
    std::string names;
    for (const auto& group : mesh_.groups)
      if (group.dim == mesh_.dim - 1) names += (names.empty() ? "" : ", ") + group.name;
    return names.empty() ? "it has none" : "it has: " + names;
  }

  std::string name_;
  const Parameters parameters_;
  MPI_Comm comm_;
  mesh::QualityReport quality_;
  mesh::Mesh mesh_;
  int n_components_;
  std::vector<int> dirichlet_tags_;
};

}  // namespace

std::unique_ptr<run::Problem> create_poisson(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<Manufactured<PoissonSolution>>("poisson", root, comm, false);
}

std::unique_ptr<run::Problem> create_elasticity(const config::Section& root, MPI_Comm comm) {
  return std::make_unique<Manufactured<ElasticitySolution>>("elasticity", root, comm, true);
}

}  // namespace coapt::problems
