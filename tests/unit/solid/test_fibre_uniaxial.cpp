// The fibre-reinforced law under homogeneous uniaxial stretch along and across the fibres:
// the Cauchy stress of the tensor implementation (materials.hpp) at F = diag(λ, t, t) against
// the closed form (uniaxial_state): lateral stresses vanish at the closed-form lateral stretch
// t, and the axial stress agrees; fibres across the axis stay slack.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "coapt/core/error.hpp"
#include "coapt/solid/materials.hpp"

namespace coapt::solid {
namespace {

FibreReinforced leaflet(int families) {
  FibreReinforced law;
  law.shear_modulus = 50e3;
  law.bulk_modulus = 500e3;
  law.fibre_k1 = 200e3;
  law.fibre_k2 = 5.0;
  law.n_fibre_families = families;
  return law;
}

// F = λ e⊗e + t (I − e⊗e) for the axis e = x.
Matrix3 uniaxial(double stretch, double lateral) {
  return Eigen::Vector3d(stretch, lateral, lateral).asDiagonal();
}

void check(const FibreReinforced& law, const FibreDirections& fibres, double stretch,
           bool expect_fibre_stress) {
  const auto state = uniaxial_state(law, fibres, Vector3::UnitX(), stretch);
  const Matrix3 sigma = cauchy(law, uniaxial(stretch, state.lateral_stretch), fibres);
  const double scale = law.shear_modulus * std::abs(stretch - 1.0);
  EXPECT_LT(std::abs(sigma(1, 1)), 1e-9 * scale) << sigma;
  EXPECT_LT(std::abs(sigma(2, 2)), 1e-9 * scale) << sigma;
  EXPECT_LT(sigma.norm() - std::abs(sigma(0, 0)), 1e-9 * scale) << sigma;  // no shear
  EXPECT_NEAR(sigma(0, 0), state.stress, 1e-10 * std::abs(state.stress));
  // The matrix alone (k₁ = 0) gives a smaller stress exactly when some fibre is taut.
  FibreReinforced matrix = law;
  matrix.fibre_k1 = 0.0;
  FibreDirections along;
  along.a0 = {Vector3::UnitX(), Vector3::UnitX()};
  const auto matrix_state = uniaxial_state(matrix, along, Vector3::UnitX(), stretch, "matrix");
  if (expect_fibre_stress)
    EXPECT_GT(state.stress - matrix_state.stress, 0.1 * scale);
  else
    EXPECT_NEAR(state.stress, matrix_state.stress, 1e-12 * std::abs(state.stress));
}

TEST(FibreUniaxial, AlongTheFibresMatchesTheClosedForm) {
  FibreDirections along;
  along.a0[0] = Vector3::UnitX();
  for (double stretch : {1.01, 1.1, 1.3}) check(leaflet(1), along, stretch, true);
  // In compression the fibre is slack: the matrix alone.
  check(leaflet(1), along, 0.9, false);
}

TEST(FibreUniaxial, AcrossTheFibresIsTheMatrixAlone) {
  FibreDirections across;
  across.a0[0] = Vector3::UnitY();
  across.a0[1] = Vector3::UnitZ();
  for (double stretch : {1.01, 1.1, 1.3}) check(leaflet(2), across, stretch, false);
}

TEST(FibreUniaxial, OneFamilyAlongOneAcross) {
  FibreDirections mixed;
  mixed.a0[0] = Vector3::UnitZ();
  mixed.a0[1] = -Vector3::UnitX();
  check(leaflet(2), mixed, 1.2, true);
}

TEST(FibreUniaxial, OtherDirectionsHaveNoClosedForm) {
  FibreDirections oblique;
  oblique.a0[0] = Vector3(1.0, 1.0, 0.0).normalized();
  EXPECT_THROW(uniaxial_state(leaflet(1), oblique, Vector3::UnitX(), 1.1), InputError);
  FibreDirections across;
  across.a0[0] = Vector3::UnitY();
  EXPECT_THROW(uniaxial_state(leaflet(1), across, Vector3::UnitX(), 0.9), InputError);
}

}  // namespace
}  // namespace coapt::solid
