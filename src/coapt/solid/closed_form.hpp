#pragma once
/// @file closed_form.hpp
/// Benchmarks of the solid against closed-form solutions, written when the case asks:
///  - uniaxial_reference: a homogeneous uniaxial stretch; the solution's mean stretch along
///    the axis, lateral stretch and axial Cauchy stress next to the closed form of the law
///    (materials.hpp, uniaxial_state) at the same stretch, and the reaction force on a
///    boundary next to σ t² A₀;
///  - lame_reference: a thick-walled cylinder under internal pressure p in plane strain; the
///    radial displacement at two probes (inner and outer radius) next to Lamé's solution
///    u_r(r) = (1 + ν) p a² / (E (b² − a²)) ((1 − 2ν) r + b²/r) with E, ν of the small-strain
///    limit of the body's law.

#include "coapt/io/json.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::solid {

/// Writes the figures of the case's closed-form references into `benchmark` (nothing when it
/// has none). Collective.
void write_closed_form_benchmark(const SolidModel& solid, io::Json& benchmark);

}  // namespace coapt::solid
