// Fibre directions per cell: the circumferential rule (directions, tilt, a point on the axis)
// and the CSV reader (header, comments, normalisation, and every kind of bad input named by
// file and line or element).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/solid/fibre_field.hpp"

namespace coapt::solid {
namespace {

FibreFieldParameters circumferential(double angle_degrees) {
  FibreFieldParameters field;
  field.rule = FibreFieldParameters::Rule::circumferential;
  field.axis = Vector3::UnitZ();
  field.point = Vector3(1.0, 2.0, 0.0);
  field.angle = angle_degrees * std::numbers::pi / 180.0;
  return field;
}

TEST(FibreField, CircumferentialIsAxisCrossRadius) {
  const auto fibres = circumferential_fibres(circumferential(0.0), Vector3(3.0, 2.0, 5.0), "cell");
  // X − point = (2, 0, 5): e_z × (2, 0, 5) = (0, 2, 0) → (0, 1, 0).
  EXPECT_NEAR((fibres.a0[0] - Vector3(0.0, 1.0, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((fibres.a0[1] - Vector3(0.0, 1.0, 0.0)).norm(), 0.0, 1e-15);
  // At (1, 5, 0): X − point = (0, 3, 0), e_z × (0, 3, 0) = (−3, 0, 0).
  const auto other = circumferential_fibres(circumferential(0.0), Vector3(1.0, 5.0, 0.0), "cell");
  EXPECT_NEAR((other.a0[0] - Vector3(-1.0, 0.0, 0.0)).norm(), 0.0, 1e-15);
}

TEST(FibreField, TiltedFamiliesAreSymmetricAboutTheCircumference) {
  const auto fibres = circumferential_fibres(circumferential(30.0), Vector3(3.0, 2.0, 0.0), "cell");
  const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
  EXPECT_NEAR((fibres.a0[0] - Vector3(0.0, c, s)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((fibres.a0[1] - Vector3(0.0, c, -s)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(fibres.a0[0].norm(), 1.0, 1e-15);
}

TEST(FibreField, CentroidOnTheAxisIsNamed) {
  try {
    circumferential_fibres(circumferential(0.0), Vector3(1.0, 2.0, 7.0), "element 42");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("element 42"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("axis"), std::string::npos) << e.what();
  }
}

std::vector<FibreDirections> read(const std::string& text,
                                  const std::vector<std::int64_t>& elements, int families = 1) {
  return fibres_from_csv(text, "fibres.csv", elements, elements.size(), families, MPI_COMM_SELF);
}

std::string error_of(const std::string& text, const std::vector<std::int64_t>& elements,
                     int families = 1) {
  try {
    read(text, elements, families);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FibreField, CsvWithHeaderAndCommentsIsReadAndNormalised) {
  const std::string text =
      "element, a1x, a1y, a1z\n# a comment\n\n7, 2, 0, 0\n3, 0, 0.5, 0\r\n5,1,1,0\n";
  const auto fibres = read(text, {3, 5, 7});
  ASSERT_EQ(fibres.size(), 3u);
  EXPECT_NEAR((fibres[0].a0[0] - Vector3(0.0, 1.0, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((fibres[1].a0[0] - Vector3(1.0, 1.0, 0.0).normalized()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((fibres[2].a0[0] - Vector3(1.0, 0.0, 0.0)).norm(), 0.0, 1e-15);
  const auto two = read("1, 1, 0, 0, 0, 0, 3\n", {1}, 2);
  EXPECT_NEAR((two[0].a0[1] - Vector3(0.0, 0.0, 1.0)).norm(), 0.0, 1e-15);
}

TEST(FibreField, CsvErrorsNameFileLineOrElement) {
  const std::string header = "element, a1x, a1y, a1z\n";
  auto message = error_of(header + "1, 1, 0, 0\n2, 0, 0, 0\n", {1, 2});
  EXPECT_NE(message.find("fibres.csv:3"), std::string::npos) << message;
  EXPECT_NE(message.find("zero"), std::string::npos) << message;

  message = error_of(header + "1, 1, 0, 0\n", {1, 2});
  EXPECT_NE(message.find("element 2"), std::string::npos) << message;
  EXPECT_NE(message.find("no row"), std::string::npos) << message;

  message = error_of(header + "1, 1, 0\n", {1});
  EXPECT_NE(message.find("fibres.csv:2"), std::string::npos) << message;
  EXPECT_NE(message.find("3 columns, expected 4"), std::string::npos) << message;

  message = error_of(header + "1, 1, 0, 0\n", {1}, 2);
  EXPECT_NE(message.find("4 columns, expected 7"), std::string::npos) << message;

  message = error_of(header + "1, 1, 0, 0\n1, 0, 1, 0\n", {1});
  EXPECT_NE(message.find("fibres.csv:3: element 1 is given again (first on line 2)"),
            std::string::npos)
      << message;

  message = error_of(header + "1, 1, 0, 0\n9, 0, 1, 0\n", {1});
  EXPECT_NE(message.find("fibres.csv:3: element 9 is not an element of the body"),
            std::string::npos)
      << message;

  message = error_of(header + "1, 1, x, 0\n", {1});
  EXPECT_NE(message.find("fibres.csv:2: 'x' is not a number"), std::string::npos) << message;

  message = error_of(header + "1, 1, 0, 0\nabc, 1, 0, 0\n", {1});
  EXPECT_NE(message.find("fibres.csv:3: 'abc' is not an element number"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace coapt::solid
