// The Hertz reference values (Johnson 1985, refs §5): the closed forms of p0 and of the
// contact size are tied by equilibrium, p0 = 2P/(πb) for a line and p0 = 3P/(2πa²) for a point,
// and agree with values worked out by hand for the cases' parameters.

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace coapt::contact
