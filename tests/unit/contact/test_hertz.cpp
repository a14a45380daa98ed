// The Hertz reference values (Johnson 1985, refs §5): the closed forms of p0 and of the
// contact size are tied by equilibrium, p0 = 2P/(πb) for a line and p0 = 3P/(2πa²) for a point,
// and agree with values worked out by hand for the cases' parameters. The nominal pressure
// is the nodal contact force over the node's reference lumped area.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "coapt/contact/solid_contact.hpp"

namespace coapt::contact {
namespace {

TEST(Hertz, LineAndPointContactFormulas) {
  HertzParameters h;
  h.radius = 1.0;
  h.young_modulus = 1.0e8;
  h.poisson_ratio = 0.3;
  h.load = 2.0e5;
  EXPECT_NEAR(h.effective_modulus(), 1.0e8 / 0.91, 1e-6);
  // b = sqrt(4 P R / (π E*)) = sqrt(8e5 · 0.91 / (π 1e8))
  EXPECT_NEAR(h.contact_size(), std::sqrt(8e5 * 0.91 / (M_PI * 1e8)), 1e-15);
  EXPECT_NEAR(h.contact_size(), 4.8138e-2, 1e-6);
  EXPECT_NEAR(h.max_pressure(), 2 * h.load / (M_PI * h.contact_size()), 1e-8 * h.max_pressure());
  h.sphere = true;
  h.load = 1.465e5;
  EXPECT_NEAR(h.contact_size(), 0.099995, 1e-5);
  const double a = h.contact_size();
  EXPECT_NEAR(h.max_pressure(), 3 * h.load / (2 * M_PI * a * a), 1e-8 * h.max_pressure());
}

TEST(Hertz, NominalPressureIsTheForcePerReferenceArea) {
  // The unit square as two triangles (0, 1, 2), (0, 2, 3): reference lumped areas 1/3, 1/6,
  // 1/3, 1/6. The mortar weights D_jj are those of a surface shrunk to 0.9 of its area.
  PairState pair;
  pair.slave = make_surface(3, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 0, 2, 3});
  const std::vector<double> reference_area{1.0 / 3, 1.0 / 6, 1.0 / 3, 1.0 / 6};
  pair.pressure = {2.0e6, 1.0e6, 0.0, 3.0e6};
  for (const double area : reference_area) pair.mortar.dual_mass.push_back(0.9 * area);
  const auto nominal = nominal_pressures(pair);
  ASSERT_EQ(nominal.size(), 4u);
  for (std::size_t j = 0; j < 4; ++j)
    EXPECT_NEAR(nominal[j], 0.9 * pair.pressure[j], 1e-9 * pair.pressure[0]) << j;

  // 2D: the segments [0, 1], [1, 3] of a polyline; lengths shared half and half.
  PairState line;
  line.slave = make_surface(2, {0, 0, 1, 0, 3, 0}, {0, 1, 1, 2});
  line.pressure = {1.0e6, 1.0e6, 1.0e6};
  line.mortar.dual_mass = {0.5, 1.5, 1.0};
  const auto nominal_line = nominal_pressures(line);
  EXPECT_NEAR(nominal_line[0], 1.0e6, 1e-3);
  EXPECT_NEAR(nominal_line[1], 1.0e6, 1e-3);
  EXPECT_NEAR(nominal_line[2], 1.0e6, 1e-3);
}

}  // namespace
}  // namespace coapt::contact
