#include "coapt/run/problem.hpp"

#include "coapt/coupling/fsci_problem.hpp"
#include "coapt/fluid/flow_problem.hpp"
#include "coapt/problems/manufactured.hpp"
#include "coapt/solid/solid_problem.hpp"
#include "coapt/transfer/transfer_problem.hpp"

namespace coapt::run {

const std::vector<ProblemKind>& problem_kinds() {
  static const std::vector<ProblemKind> kinds = {
      {"poisson", "Poisson equation with a manufactured solution (verification of the FEM core)",
       problems::create_poisson},
      {"elasticity",
       "linear elasticity with a manufactured solution (verification of the FEM core)",
       problems::create_elasticity},
      {"solid", "quasi-static finite-strain solids (P1, total Lagrangian)",
       solid::create_solid_problem},
      {"navier_stokes", "incompressible Navier-Stokes, P1-P1 SUPG/PSPG/LSIC",
       fluid::create_flow_problem},
      {"fsci", "immersed fluid-solid coupling: solids constrain the fluid over their overlap",
       coupling::create_fsci_problem},
      {"transfer",
       "variational transfer of an analytic field between two meshes (errors, conservation)",
       transfer::create_transfer_problem},
  };
  return kinds;
}

std::unique_ptr<Problem> create_problem(const config::Section& root, MPI_Comm comm) {
  std::vector<std::string> names;
  for (const auto& kind : problem_kinds()) names.push_back(kind.name);
  const std::string name = root.choice("problem", "", names, {"", "what the case simulates"});
  for (const auto& kind : problem_kinds())
    if (kind.name == name) return kind.create(root, comm);
  root.fail("problem", "unknown problem");
}

}  // namespace coapt::run
