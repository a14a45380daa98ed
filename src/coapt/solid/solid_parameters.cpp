// Reading the `problem: solid` case sections (see solid_parameters.hpp for the format).
#include "coapt/solid/solid_parameters.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "coapt/core/error.hpp"
#include "coapt/fem/line_search.hpp"

namespace coapt::solid {

using config::Bounds;

namespace {

int component_index(const config::Section& section, const std::string& name) {
  if (name == "x") return 0;
  if (name == "y") return 1;
  if (name == "z") return 2;
  section.fail("components", fmt::format("unknown component '{}' (use x, y, z)", name));
}

}  // namespace

Material read_material(const config::Section& section) {
  const std::string model =
      section.choice("model", "",
                     {"linear_elastic", "saint_venant_kirchhoff", "neo_hookean",
                      "nearly_incompressible_neo_hookean", "fibre_reinforced"},
                     {"", "constitutive law"});
  const std::string where = section.located();
  // Elastic constants: (young_modulus, poisson_ratio) or (shear_modulus with one of
  // poisson_ratio, lambda, bulk_modulus); the rest follows from the isotropic relations
  // λ = 2μν/(1 − 2ν), κ = λ + 2μ/3.
  const bool has_young = section.has("young_modulus");
  const bool has_shear = section.has("shear_modulus");
  if (has_young == has_shear)
    section.fail("", "give either young_modulus or shear_modulus (exactly one)");
  double mu = 0, lambda = 0;
  if (has_young) {
    const double young =
        section.require<double>("young_modulus", {"Pa", "Young's modulus E", Bounds::positive()});
    const double poisson =
        section.require<double>("poisson_ratio", {"", "Poisson's ratio", Bounds::open(-1.0, 0.5)});
    const LameParameters lame = lame_from_young_poisson(young, poisson, where);
    mu = lame.mu;
    lambda = lame.lambda;
  } else {
    mu = section.require<double>("shear_modulus", {"Pa", "shear modulus μ", Bounds::positive()});
    const int given = int(section.has("poisson_ratio")) + int(section.has("lambda")) +
                      int(section.has("bulk_modulus"));
    if (given != 1)
      section.fail("shear_modulus",
                   "with shear_modulus give exactly one of poisson_ratio, lambda, bulk_modulus");
    if (section.has("poisson_ratio")) {
      const double poisson = section.require<double>(
          "poisson_ratio", {"", "Poisson's ratio", Bounds::open(-1.0, 0.5)});
      lambda = 2.0 * mu * poisson / (1.0 - 2.0 * poisson);
    } else if (section.has("lambda")) {
      lambda = section.require<double>("lambda", {"Pa", "first Lamé constant λ"});
    } else {
      lambda =
          section.require<double>("bulk_modulus", {"Pa", "bulk modulus κ", Bounds::positive()}) -
          2.0 / 3.0 * mu;
    }
  }
  const double bulk = lambda + 2.0 / 3.0 * mu;
  Material material;
  if (model == "linear_elastic")
    material = LinearElastic{lambda, mu};
  else if (model == "saint_venant_kirchhoff")
    material = SaintVenantKirchhoff{lambda, mu};
  else if (model == "neo_hookean")
    material = NeoHookean{lambda, mu};
  else if (model == "nearly_incompressible_neo_hookean")
    material = NearlyIncompressibleNeoHookean{mu, bulk};
  else {
    FibreReinforced law;
    law.shear_modulus = mu;
    law.bulk_modulus = bulk;
    law.fibre_k1 =
        section.require<double>("fibre_k1", {"Pa", "fibre stiffness k1", Bounds::non_negative()});
    law.fibre_k2 =
        section.get<double>("fibre_k2", 0.0, {"", "fibre stiffening k2", Bounds::non_negative()});
    law.n_fibre_families = section.get<int>("fibre_families", 1,
                                            {"", "number of fibre families", Bounds::closed(1, 2)});
    material = law;
  }
  validate(material, where);
  return material;
}

SolidParameters SolidParameters::read(const config::Section& root) {
  SolidParameters p;
  p.mesh = mesh::MeshInput::read(root.section("mesh", "the mesh"), root.case_directory());

  const auto bodies = root.sections("bodies", "the solid bodies (cell groups with a material)");
  if (bodies.empty()) root.fail("bodies", "at least one body is required");
  int catch_all = 0;
  for (const auto& section : bodies) {
    BodyParameters body;
    body.where = section.located();
    body.name = section.get<std::string>("name", "body", {"", "name of the body"});
    body.cell_groups = section.get<std::vector<std::string>>(
        "cell_groups", {}, {"", "mesh cell groups of the body (empty: all remaining cells)"});
    if (body.cell_groups.empty() && ++catch_all > 1)
      section.fail("cell_groups", "only one body may omit cell_groups");
    body.density = section.get<double>("density", 0.0,
                                       {"kg/m^3", "reference density", Bounds::non_negative()});
    body.material = read_material(section.section("material", "constitutive law"));
    body.initial_velocity = section.get<std::vector<double>>(
        "initial_velocity", {},
        {"m/s",
         "dynamics: initial velocity of the body's free dofs (empty: time.initial_velocity)"});
    if (const auto* fibre_law = std::get_if<FibreReinforced>(&body.material)) {
      body.fibre_field = FibreFieldParameters::read(section, fibre_law->n_fibre_families);
      if (body.fibre_field.rule == FibreFieldParameters::Rule::constant) {
        body.fibres = body.fibre_field.constant;
        validate_fibres(body.material, body.fibres, body.fibre_field.where);
      }
    }
    p.bodies.push_back(std::move(body));
  }

  for (const auto& section : root.sections("dirichlet", "prescribed displacements")) {
    DirichletParameters condition;
    condition.where = section.located();
    condition.boundary = section.require<std::string>("boundary", {"", "boundary group"});
    const auto names = section.get<std::vector<std::string>>(
        "components", {}, {"", "prescribed components x, y, z (empty: all)"});
    for (const auto& name : names) condition.components.push_back(component_index(section, name));
    condition.values = section.get<std::vector<double>>(
        "displacement", {}, {"m", "final displacement per listed component (empty: zero)"});
    if (!condition.values.empty() && !names.empty() && condition.values.size() != names.size())
      section.fail("displacement", "expected one value per entry of components");
    const auto ramp = section.get<std::vector<double>>(
        "ramp", {0.0, 1.0},
        {"",
         "load-factor interval [start, end] over which the displacement ramps from 0 to its "
         "value (0 before, full after; static load steps)"});
    if (ramp.size() != 2 || !(0.0 <= ramp[0] && ramp[0] < ramp[1] && ramp[1] <= 1.0))
      section.fail("ramp",
                   fmt::format("expected [start, end] with 0 <= start < end <= 1 (got [{}])",
                               fmt::join(ramp, ", ")));
    condition.ramp_start = ramp[0];
    condition.ramp_end = ramp[1];
    condition.ramped = section.has("ramp");
    p.dirichlet.push_back(std::move(condition));
  }
  if (p.dirichlet.empty())
    root.fail("dirichlet",
              "at least one Dirichlet condition is required (a static solid needs "
              "its rigid motions fixed)");

  for (const auto& section : root.sections("tractions", "dead loads on boundary groups")) {
    TractionParameters load;
    load.where = section.located();
    load.boundary = section.require<std::string>("boundary", {"", "boundary group"});
    const bool has_traction = section.has("traction"), has_total = section.has("total_force");
    if (has_traction == has_total)
      section.fail("", "give either traction or total_force (exactly one)");
    load.total = has_total;
    load.vector = has_total ? section.require<std::vector<double>>(
                                  "total_force", {"N", "total force, spread uniformly (N/m in 2D)"})
                            : section.require<std::vector<double>>(
                                  "traction", {"Pa", "force per reference area (length in 2D)"});
    p.tractions.push_back(std::move(load));
  }

  for (const auto& section : root.sections(
           "pressures", "follower pressures on boundary groups (current configuration)")) {
    PressureParameters load;
    load.where = section.located();
    load.boundary = section.require<std::string>("boundary", {"", "boundary group"});
    load.pressure = section.require<double>(
        "pressure", {"Pa", "pressure p: load -p n da on the current boundary (n outward)"});
    p.pressures.push_back(std::move(load));
  }

  p.gravity = root.get<std::vector<double>>("gravity", {}, {"m/s^2", "gravity (body force ρ g)"});
  p.gravity_where = root.located("gravity");
  p.steps = root.get<int>("steps", 1, {"", "load steps", Bounds::closed(1, 100000)});

  auto newton = root.section("newton", "Newton's method per load step");
  p.newton.relative_tolerance =
      newton.get<double>("relative_tolerance", 1e-9,
                         {"", "stop when |R| <= rtol |R0| (free dofs)", Bounds::open(0.0, 1.0)});
  p.newton.absolute_tolerance = newton.get<double>(
      "absolute_tolerance", 0.0, {"N", "or when |R| <= atol (N/m in 2D)", Bounds::non_negative()});
  p.newton.update_tolerance = newton.get<double>(
      "update_tolerance", 1e-12,
      {"", "or when |du| <= dtol |u| (round-off floor of R)", Bounds::closed(0.0, 1e-3)});
  p.newton.max_iterations = newton.get<int>(
      "max_iterations", 25, {"", "iterations per load step", Bounds::closed(1, 1000)});
  p.newton.line_search = fem::read_line_search(newton);
  p.newton.reuse_factorisation = newton.get<int>(
      "reuse_factorisation", 0,
      {"",
       "dynamics: a time step's first factorisation preconditions GMRES (the solid's KSP "
       "then) in the step's later Newton and coupling iterations until a solve on it needs "
       "more than this many iterations; then it is factored afresh. 0: factored at every "
       "Newton iteration",
       Bounds::closed(0, 100)});
  p.newton.reuse_where = newton.located("reuse_factorisation");
  p.newton.extrapolate =
      newton.choice("predictor", "previous", {"previous", "extrapolate"},
                    {"",
                     "initial iterate of a load step: previous (the last solution) or "
                     "extrapolate (linearly from the last two; static, displacement "
                     "formulation)"}) == "extrapolate";

  auto time = root.section("time", "time integration (static load stepping or Newmark)");
  p.time.where = time.located();
  const auto scheme = time.choice(
      "scheme", "static", {"static", "newmark", "contact_stabilized_newmark"},
      {"",
       "static: load steps; newmark: dynamics, beta 1/4, gamma 1/2; "
       "contact_stabilized_newmark: Newmark with lumped mass and the predictor projected onto "
       "the admissible set (Deuflhard-Krause-Ertel)"});
  p.time.dynamic = scheme != "static";
  p.time.contact_stabilized = scheme == "contact_stabilized_newmark";
  if (p.time.dynamic) {
    p.time.step = time.require<double>("step", {"s", "time step", Bounds::positive()});
    p.time.end_time = time.require<double>("end_time", {"s", "final time", Bounds::positive()});
    const double ratio = p.time.end_time / p.time.step;
    p.time.n_steps = static_cast<int>(std::lround(ratio));
    if (p.time.n_steps < 1 || std::abs(ratio - p.time.n_steps) > 1e-6 * ratio)
      time.fail("end_time",
                fmt::format("end_time = {:g} s is not a whole number of steps of {:g} s",
                            p.time.end_time, p.time.step));
    p.time.initial_velocity = time.get<std::vector<double>>(
        "initial_velocity", {}, {"m/s", "uniform initial velocity of the free dofs (empty: rest)"});
    if (root.has("steps"))
      root.fail("steps",
                "load steps are for the static scheme; with time.scheme = newmark the "
                "loads act in full from t = 0 (remove steps)");
  }

  for (const auto& condition : p.dirichlet)
    if (condition.ramped && p.time.dynamic)
      throw InputError(fmt::format(
          "{}.ramp: a ramp interval is for static load steps; with time.scheme = {} the "
          "prescribed displacements act in full from t = 0 (remove ramp)",
          condition.where, scheme));

  for (const auto& section : root.sections("probes", "points where the displacement is reported")) {
    ProbeParameters probe;
    probe.where = section.located();
    probe.name = section.require<std::string>("name", {"", "name in series.csv and summary.json"});
    probe.point = section.require<std::vector<double>>("point", {"m", "reference coordinates"});
    p.probes.push_back(std::move(probe));
  }

  p.reaction_boundaries = root.get<std::vector<std::string>>(
      "reactions", {},
      {"", "boundary groups whose reaction force goes to series.csv and summary.json (static)"});
  if (!p.reaction_boundaries.empty() && p.time.dynamic)
    root.fail("reactions", "reaction forces are reported for the static scheme only");

  if (root.has("uniaxial_reference")) {
    auto section = root.section("uniaxial_reference",
                                "compare a homogeneous uniaxial stretch with its closed form");
    p.uniaxial.enabled = true;
    p.uniaxial.where = section.located();
    const auto axis = section.require<std::vector<double>>("axis", {"", "stretch axis (3D)"});
    if (axis.size() != 3) section.fail("axis", "expected 3 components (a 3D case)");
    p.uniaxial.axis = Vector3(axis[0], axis[1], axis[2]);
    if (!(p.uniaxial.axis.norm() > 0.0)) section.fail("axis", "must be non-zero");
    p.uniaxial.axis.normalize();
    p.uniaxial.reaction_boundary = section.get<std::string>(
        "reaction_boundary", "", {"", "boundary whose reaction force is reported (empty: none)"});
    p.uniaxial.reference_area =
        section.get<double>("reference_area", 0.0,
                            {"m^2", "reference area of reaction_boundary", Bounds::non_negative()});
    if (p.bodies.size() != 1) section.fail("", "the closed form is for one body");
    const auto& material = p.bodies.front().material;
    const auto* fibre = std::get_if<FibreReinforced>(&material);
    if (!fibre && !std::holds_alternative<NearlyIncompressibleNeoHookean>(material))
      section.fail("",
                   "the closed form is for nearly_incompressible_neo_hookean or "
                   "fibre_reinforced");
    if (fibre && p.bodies.front().fibre_field.rule != FibreFieldParameters::Rule::constant)
      section.fail("", "the closed form needs constant fibre directions");
  }

  if (root.has("lame_reference")) {
    auto section = root.section("lame_reference",
                                "compare an inflated thick-walled cylinder with Lame's solution");
    p.lame.enabled = true;
    p.lame.where = section.located();
    p.lame.inner_radius =
        section.require<double>("inner_radius", {"m", "inner radius a", Bounds::positive()});
    p.lame.outer_radius =
        section.require<double>("outer_radius", {"m", "outer radius b", Bounds::positive()});
    if (!(p.lame.outer_radius > p.lame.inner_radius))
      section.fail("outer_radius", "must exceed inner_radius");
    p.lame.inner_probe = section.require<std::string>(
        "inner_probe", {"", "probe at r = a (its radial displacement)"});
    p.lame.outer_probe = section.require<std::string>(
        "outer_probe", {"", "probe at r = b (its radial displacement)"});
    if (p.bodies.size() != 1) section.fail("", "Lame's solution is for one body");
    if (p.pressures.size() != 1)
      section.fail("", "Lame's solution needs exactly one entry in pressures (the inner one)");
    if (std::holds_alternative<FibreReinforced>(p.bodies.front().material))
      section.fail("", "Lame's solution is for an isotropic material");
  }

  p.mixed = root.choice("formulation", "displacement", {"displacement", "mixed"},
                        {"",
                         "displacement, or mixed: P1-P1 displacement-pressure against locking "
                         "(nearly incompressible laws, static)"}) == "mixed";
  if (p.newton.extrapolate && (p.mixed || p.time.dynamic))
    newton.fail("predictor",
                "extrapolate is for static load steps of the displacement formulation");
  if (p.mixed) {
    if (p.time.dynamic)
      root.fail("formulation", "the mixed formulation is static only (time.scheme: static)");
    for (const auto& body : p.bodies)
      if (!std::holds_alternative<NearlyIncompressibleNeoHookean>(body.material) &&
          !std::holds_alternative<FibreReinforced>(body.material))
        root.fail("formulation",
                  fmt::format("the mixed formulation needs a law with a bulk modulus "
                              "(nearly_incompressible_neo_hookean or fibre_reinforced); body '{}' "
                              "is {}",
                              body.name, name(body.material)));
  }

  auto output = root.section("output", "what the run writes");
  p.write_vtk = output.get<bool>("vtk", true, {"", "write displacement and stresses as VTK"});
  p.vtk_interval = output.get<int>(
      "vtk_interval", 1,
      {"", "time steps between VTK files (newmark scheme)", Bounds::closed(1, 1000000)});
  p.checkpoint_interval =
      output.get<int>("checkpoint_interval", 0,
                      {"", "time steps between checkpoints for --restart (newmark scheme; 0: none)",
                       Bounds::closed(0, 1000000)});
  return p;
}

void SolidParameters::check_dimension(int dim) const {
  const auto check = [dim](std::size_t size, const std::string& where, const char* what) {
    if (static_cast<int>(size) != dim)
      throw InputError(
          fmt::format("{}: {} has {} entries, the mesh has dimension {}", where, what, size, dim));
  };
  for (const auto& condition : dirichlet) {
    for (int component : condition.components)
      if (component >= dim)
        throw InputError(fmt::format("{}: component z in a 2D mesh", condition.where));
    if (condition.components.empty() && !condition.values.empty())
      check(condition.values.size(), condition.where, "displacement");
  }
  for (const auto& load : tractions) check(load.vector.size(), load.where, "the load vector");
  if (!gravity.empty()) check(gravity.size(), gravity_where, "gravity");
  if (!time.initial_velocity.empty())
    check(time.initial_velocity.size(), time.where + ".initial_velocity", "initial_velocity");
  for (const auto& body : bodies)
    if (!body.initial_velocity.empty())
      check(body.initial_velocity.size(), body.where + ".initial_velocity", "initial_velocity");
  for (const auto& probe : probes) check(probe.point.size(), probe.where, "point");
  if (dim == 2)
    for (const auto& body : bodies)
      if (std::holds_alternative<FibreReinforced>(body.material)) {
        const auto& field = body.fibre_field;
        for (const auto& a0 : body.fibres.a0)
          if (a0.z() != 0.0)
            throw InputError(
                fmt::format("{}: plane strain needs fibres in the x-y plane", field.where));
        if (field.rule == FibreFieldParameters::Rule::circumferential &&
            (std::abs(field.axis.z()) != 1.0 || field.angle != 0.0))
          throw InputError(fmt::format(
              "{}: plane strain needs fibres in the x-y plane: axis [0, 0, 1] and angle 0",
              field.where));
      }
}

}  // namespace coapt::solid
