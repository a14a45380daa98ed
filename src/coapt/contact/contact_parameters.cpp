// Reading the `contact:` section (contact_parameters.hpp).
#include "coapt/contact/contact_parameters.hpp"

#include <fmt/format.h>

namespace coapt::contact {

using config::Bounds;

ContactParameters ContactParameters::read(const config::Section& root) {
  ContactParameters p;
  if (!root.has("contact")) return p;
  const auto section =
      root.section("contact", "frictionless mortar contact between boundary groups");
  p.where = section.where();
  for (const auto& pair : section.sections("pairs", "master/slave pairs of boundary groups")) {
    ContactPair c;
    c.slave = pair.require<std::string>(
        "slave", {"", "boundary group carrying the contact pressure (the finer side)"});
    c.master = pair.require<std::string>("master", {"", "boundary group the slave may touch"});
    c.where = pair.where();
    if (c.slave == c.master) pair.fail("master", "a group cannot be in contact with itself");
    p.pairs.push_back(std::move(c));
  }
  if (p.pairs.empty()) section.fail("pairs", "give at least one pair {slave: ..., master: ...}");
  p.complementarity_constant =
      section.get<double>("complementarity_constant", 0.0,
                          {"Pa/m", "c in the active-set test p - c g > 0 (0: from the stiffness)",
                           Bounds::non_negative()});
  p.search_distance = section.get<double>(
      "search_distance", 0.0,
      {"m",
       "master facets farther from a slave facet are ignored (0: 10 times the mean "
       "slave facet size)",
       Bounds::non_negative()});
  p.relative_gap_tolerance =
      section.get<double>("relative_gap_tolerance", 1e-8,
                          {"", "gaps below this times the mean slave facet size count as closed",
                           Bounds::closed(0.0, 0.1)});
  p.coverage_threshold =
      section.get<double>("coverage_threshold", 1.0 - 1e-8,
                          {"",
                           "covered fraction of a slave node's support needed to constrain it "
                           "(1 - 1e-8: the whole support; lower: contact follows a slave node "
                           "past a master's end)",
                           {0.0, 1.0, true, false}});
  p.boundary_modification = section.get<bool>(
      "boundary_modification", true,
      {"", "no multipliers on the boundary nodes of slave surfaces (modified dual basis)"});
  p.max_active_set_changes =
      section.get<int>("max_active_set_changes", 30,
                       {"", "Newton iterations of a step in which the active set may still change",
                        Bounds::closed(1, 1000)});
  p.finite_difference_geometry =
      section.choice("linearisation", "frozen", {"frozen", "finite_difference"},
                     {"",
                      "the contact rows' Newton tangent: frozen (the mortar geometry held at "
                      "the iterate: linear convergence where the contact zone rotates or "
                      "slides) or finite_difference (its derivative by central differences of "
                      "the surface nodes' positions)"}) == "finite_difference";
  return p;
}

}  // namespace coapt::contact
