#include <gtest/gtest.h>

#include "coapt/core/config.hpp"
#include "coapt/core/error.hpp"

namespace {

using coapt::InputError;
using coapt::config::Bounds;
using coapt::config::Document;

std::string message_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

const char* kCase = R"(problem: poisson
fluid:
  density: 1000
  viscosity: 1e-3
  inlet: [0.1, 0.2]
solids:
  - name: leaflet
    density: 1100
  - name: stent
)";

TEST(Config, ReadsValuesAndDefaults) {
  auto doc = Document::from_string(kCase, "case.yaml");
  auto root = doc.root();
  EXPECT_EQ(root.get<std::string>("problem", "", {"", "driver"}), "poisson");
  auto fluid = root.section("fluid");
  EXPECT_DOUBLE_EQ(fluid.get<double>("density", 1.0, {"kg/m^3", "", Bounds::positive()}), 1000.0);
  EXPECT_DOUBLE_EQ(fluid.get<double>("viscosity", 1.0, {"Pa s", ""}), 1e-3);
  EXPECT_EQ(fluid.get<std::vector<double>>("inlet", {}, {"m/s", ""}).size(), 2u);
  EXPECT_EQ(fluid.get<int>("steps", 7, {"", ""}), 7);
  auto solids = root.sections("solids");
  ASSERT_EQ(solids.size(), 2u);
  EXPECT_DOUBLE_EQ(solids[0].get<double>("density", 1.0, {"kg/m^3", ""}), 1100.0);
  EXPECT_DOUBLE_EQ(solids[1].get<double>("density", 1.0, {"kg/m^3", ""}), 1.0);
  for (auto& s : solids) s.require<std::string>("name", {"", ""});
  EXPECT_NO_THROW(doc.reject_unknown_keys());
  const std::string resolved = doc.resolved_yaml();
  EXPECT_NE(resolved.find("steps: 7"), std::string::npos) << resolved;
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  auto doc = Document::from_string("fluid:\n  density: 1\n  viscocity: 2\n", "c.yaml");
  doc.root().section("fluid").get<double>("density", 1.0, {"", ""});
  doc.root().section("fluid").get<double>("viscosity", 1.0, {"", ""});
  const auto message = message_of([&] { doc.reject_unknown_keys(); });
  EXPECT_NE(message.find("c.yaml:3: fluid.viscocity: unknown key"), std::string::npos) << message;
}

TEST(Config, WrongTypeAndRangeAreRejectedWithLocation) {
  auto doc =
      Document::from_string("fluid:\n  density: heavy\n  viscosity: -1\n  n: 2.5\n", "c.yaml");
  auto fluid = doc.root().section("fluid");
  auto m1 = message_of([&] { fluid.get<double>("density", 1.0, {"kg/m^3", ""}); });
  EXPECT_NE(m1.find("c.yaml:2: fluid.density: expected a number"), std::string::npos) << m1;
  auto m2 = message_of([&] {
    fluid.get<double>("viscosity", 1.0, {"Pa s", "", Bounds::positive()});
  });
  EXPECT_NE(m2.find("c.yaml:3: fluid.viscosity: value -1 is out of range: must be > 0"),
            std::string::npos)
      << m2;
  auto m3 = message_of([&] { fluid.get<int>("n", 1, {"", ""}); });
  EXPECT_NE(m3.find("c.yaml:4: fluid.n: expected an integer"), std::string::npos) << m3;
}

TEST(Config, MissingRequiredKeyNamesTheSection) {
  auto doc = Document::from_string("mesh:\n  level: 1\n", "c.yaml");
  auto m = message_of([&] { doc.root().section("mesh").require<std::string>("file", {"", ""}); });
  EXPECT_NE(m.find("mesh.file: required key is missing"), std::string::npos) << m;
}

TEST(Config, SetOverridesWithTheSameChecks) {
  auto doc = Document::from_string(kCase, "case.yaml");
  doc.set("fluid.viscosity=2e-3");
  doc.set("mesh.level=3");
  doc.set("solids[1].density=900");
  auto root = doc.root();
  EXPECT_DOUBLE_EQ(root.section("fluid").get<double>("viscosity", 1.0, {"", ""}), 2e-3);
  EXPECT_EQ(root.section("mesh").get<int>("level", 0, {"", ""}), 3);
  EXPECT_DOUBLE_EQ(root.sections("solids")[1].get<double>("density", 1.0, {"", ""}), 900.0);
  doc.set("fluid.density=-5");
  auto m = message_of([&] {
    root.section("fluid").get<double>("density", 1.0, {"", "", Bounds::positive()});
  });
  EXPECT_NE(m.find("--set fluid.density=-5: fluid.density: value -5 is out of range"),
            std::string::npos)
      << m;
  EXPECT_NE(message_of([&] { doc.set("novalue"); }).find("expected key.path=value"),
            std::string::npos);
  EXPECT_NE(message_of([&] { doc.set("fluid.density.x=1"); }).find("inside a value"),
            std::string::npos);
}

TEST(Config, MalformedYamlAndMissingFile) {
  auto m1 = message_of([] { Document::from_string("a: [1, 2\nb: 3\n", "bad.yaml"); });
  EXPECT_NE(m1.find("bad.yaml:"), std::string::npos) << m1;
  EXPECT_NE(m1.find("malformed YAML"), std::string::npos) << m1;
  auto m2 = message_of([] { Document::from_file("/nonexistent/case.yaml"); });
  EXPECT_NE(m2.find("/nonexistent/case.yaml: cannot open the case file (no such file)"),
            std::string::npos)
      << m2;
}

TEST(Config, ChoiceRejectsUnlistedValue) {
  auto doc = Document::from_string("solver: magic\n", "c.yaml");
  auto m = message_of([&] {
    doc.root().choice("solver", "direct", {"direct", "iterative"}, {"", ""});
  });
  EXPECT_NE(m.find("c.yaml:1: solver: 'magic' is not one of: direct | iterative"),
            std::string::npos)
      << m;
}

TEST(Config, RecordsDocumentation) {
  auto doc = Document::from_string("", "c.yaml");
  doc.root().section("fluid").get<double>("viscosity", 1e-3,
                                          {"Pa s", "dynamic viscosity", Bounds::positive()});
  ASSERT_EQ(doc.keys().size(), 2u);
  EXPECT_EQ(doc.keys()[1].path, "fluid.viscosity");
  EXPECT_EQ(doc.keys()[1].unit, "Pa s");
  EXPECT_EQ(doc.keys()[1].range, "> 0");
}

}  // namespace
