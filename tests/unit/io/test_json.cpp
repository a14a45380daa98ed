#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/io/json.hpp"

namespace {

using coapt::io::Json;

Json nested() {
  Json j;
  j["case"] = "cylinder";
  j["steps"] = 120;
  j["converged"] = true;
  j["nothing"] = nullptr;
  j["drag"] = Json::array({1.5, 0.1, -2.0});
  j["fluid"]["iterations"].push_back(3);
  j["fluid"]["iterations"].push_back(4);
  j["fluid"]["empty_list"] = Json::array();
  j["fluid"]["empty_object"] = Json::object();
  return j;
}

TEST(Json, DumpsNestedValuesCompact) {
  EXPECT_EQ(nested().dump(-1),
            R"({"case":"cylinder","steps":120,"converged":true,"nothing":null,)"
            R"("drag":[1.5,0.1,-2.0],"fluid":{"iterations":[3,4],"empty_list":[],)"
            R"("empty_object":{}}})");
}

TEST(Json, DumpsNestedValuesIndented) {
  const std::string expected = R"({
  "case": "cylinder",
  "steps": 120,
  "converged": true,
  "nothing": null,
  "drag": [
    1.5,
    0.1,
    -2.0
  ],
  "fluid": {
    "iterations": [
      3,
      4
    ],
    "empty_list": [],
    "empty_object": {}
  }
})";
  EXPECT_EQ(nested().dump(2), expected);
  EXPECT_EQ(Json::array({1, Json::array({2})}).dump(0), "[\n1,\n[\n2\n]\n]");
}

TEST(Json, ScalarsAtTopLevel) {
  EXPECT_EQ(Json().dump(), "null");
  EXPECT_EQ(Json(false).dump(), "false");
  EXPECT_EQ(Json(-7).dump(), "-7");
  EXPECT_EQ(Json(std::int64_t{9007199254740993}).dump(), "9007199254740993");
  EXPECT_EQ(Json(std::size_t{42}).dump(), "42");
  EXPECT_EQ(Json("x").dump(), "\"x\"");
  EXPECT_EQ(Json(std::string("y")).dump(), "\"y\"");
}

TEST(Json, NumbersAsPythonReprWritesThem) {
  // Python: [repr(x) for x in (3.0, 0.1, 1e-05, 0.0001, 1e16, 1e15, 123.456, -0.0, 5e-324,
  // 1.7976931348623157e308, 2.5e-07, 1/3)]
  const std::vector<std::pair<double, std::string>> cases = {
      {3.0, "3.0"},
      {0.1, "0.1"},
      {1e-05, "1e-05"},
      {0.0001, "0.0001"},
      {1e16, "1e+16"},
      {1e15, "1000000000000000.0"},
      {123.456, "123.456"},
      {-0.0, "-0.0"},
      {5e-324, "5e-324"},
      {1.7976931348623157e308, "1.7976931348623157e+308"},
      {2.5e-07, "2.5e-07"},
      {1.0 / 3.0, "0.3333333333333333"},
      {12345678901234567.0, "1.2345678901234568e+16"},
  };
  for (const auto& [value, text] : cases) {
    EXPECT_EQ(Json(value).dump(), text);
    EXPECT_EQ(Json::parse(text).as_double(), value) << text;
  }
}

TEST(Json, EscapesStringsPerTheSpec) {
  const std::string raw = std::string("quote\" backslash\\ slash/ \b\f\n\r\t ctl") + '\x01' +
                          '\x1f' + " del\x7f utf8 \xc3\xa9";
  const std::string expected = R"("quote\" backslash\\ slash/ \b\f\n\r\t ctl\u0001\u001f del)"
                               "\x7f utf8 \xc3\xa9\"";
  EXPECT_EQ(Json(raw).dump(), expected);
  Json object;
  object["key \"with\" quotes\n"] = 1;
  EXPECT_EQ(object.dump(-1), R"({"key \"with\" quotes\n":1})");
  EXPECT_EQ(Json::parse(expected).as_string(), raw);
  EXPECT_EQ(Json::parse(R"("\u00e9\ud83d\ude00\/")").as_string(), "\xc3\xa9\xf0\x9f\x98\x80/");
}

TEST(Json, NonFiniteNumbersAreNullAndDetected) {
  Json j;
  j["ok"] = 1.0;
  EXPECT_FALSE(j.has_non_finite());
  j["list"] = Json::array({1.0, 2.0});
  j["deep"]["deeper"] = Json::array({0.0, std::numeric_limits<double>::quiet_NaN()});
  EXPECT_TRUE(j.has_non_finite());
  j["inf"] = std::numeric_limits<double>::infinity();
  j["minus_inf"] = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(j.dump(-1), R"({"ok":1.0,"list":[1.0,2.0],"deep":{"deeper":[0.0,null]},"inf":null,)"
                        R"("minus_inf":null})");
  EXPECT_TRUE(Json(std::numeric_limits<double>::infinity()).has_non_finite());
  EXPECT_FALSE(Json::array({Json(), Json("nan")}).has_non_finite());
}

TEST(Json, ObjectsKeepInsertionOrderAndReplaceValues) {
  Json j = Json::object({{"b", 1}, {"a", 2}, {"b", 3}});
  EXPECT_EQ(j.dump(-1), R"({"b":3,"a":2})");
  j["c"] = "x";
  j["a"] = Json::array();
  EXPECT_EQ(j.dump(-1), R"({"b":3,"a":[],"c":"x"})");
  EXPECT_EQ(j.size(), 3u);
  EXPECT_TRUE(j.contains("a"));
  EXPECT_FALSE(j.contains("z"));
  EXPECT_EQ(j.at("b").as_int(), 3);
  EXPECT_THROW(j.at("z"), coapt::InternalError);
}

TEST(Json, WrongTypesThrowInternalError) {
  Json number = 1.0;
  EXPECT_THROW(number["key"], coapt::InternalError);
  EXPECT_THROW(number.push_back(1), coapt::InternalError);
  EXPECT_THROW(number.as_string(), coapt::InternalError);
  Json array = Json::array({1});
  EXPECT_THROW(array.at(1), coapt::InternalError);
  EXPECT_EQ(array.at(0).as_double(), 1.0);
}

TEST(Json, ParsesWhatItDumps) {
  const Json original = nested();
  EXPECT_EQ(Json::parse(original.dump(2)), original);
  EXPECT_EQ(Json::parse(original.dump(-1)), original);
  EXPECT_EQ(Json::parse(" [ 1 , -2.5e3 , 1E2, 0 ] ").dump(-1), "[1,-2500.0,100.0,0]");
  // Integers too large for int64 become doubles.
  EXPECT_EQ(Json::parse("123456789012345678901").type(), Json::Type::number);
  for (const char* bad : {"", "[1,]", "{\"a\" 1}", "01", "\"abc", "[1] x", "nul", "1.", "-",
                          "\"\\x\"", "\"\\ud800\"", "{1:2}"})
    EXPECT_THROW(Json::parse(bad), coapt::InputError) << bad;
}

TEST(Json, WritesFiles) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("coapt_test_json_" + std::to_string(::getpid()) + ".json");
  nested().write_file(path, 2);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), nested().dump(2) + "\n");
  std::filesystem::remove(path);
  EXPECT_THROW(nested().write_file("/nonexistent-dir/x.json"), coapt::Error);
}

}  // namespace
