#include "coapt/run/problem.hpp"

#include "coapt/problems/manufactured.hpp"

namespace coapt::run {

const std::vector<ProblemKind>& problem_kinds() {
  static const std::vector<ProblemKind> kinds = {
      {"poisson", "Poisson equation with a manufactured solution (verification of the FEM core)",
       problems::create_poisson},
      {"elasticity",
       "linear elasticity with a manufactured solution (verification of the FEM core)",
       problems::create_elasticity},
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
