// TimeWaveform (fluid_model.hpp): the tabulated factor read from the case (`table`) and from a
// CSV file (`csv`): the same factor from both, periodic repetition, and bad files reported
// with the file and line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "coapt/core/config.hpp"
#include "coapt/core/error.hpp"
#include "coapt/fluid/fluid_model.hpp"

namespace {

using coapt::fluid::TimeWaveform;

/// A fresh folder for one test's files.
std::filesystem::path test_folder(const std::string& name) {
  const auto folder = std::filesystem::temp_directory_path() / ("coapt_waveform_" + name);
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  return folder;
}

TimeWaveform read_waveform(const std::filesystem::path& folder, const std::string& yaml) {
  auto document = coapt::config::Document::from_string(yaml, (folder / "case.yaml").string());
  return TimeWaveform::read(document.root().section("waveform", "the waveform"));
}

std::string error_of(const std::filesystem::path& folder, const std::string& yaml) {
  try {
    read_waveform(folder, yaml);
  } catch (const coapt::InputError& error) {
    return error.what();
  }
  return "";
}

TEST(TimeWaveform, CsvFileGivesTheTableOfTheCase) {
  const auto folder = test_folder("same");
  std::ofstream(folder / "inflow.csv") << "# an aortic-like pulse\ntime,factor\n0, 0\n0.1, 1.0\n"
                                          "0.3,0.25\n\n0.8, 0  # end of the period\n";
  const auto csv = read_waveform(folder, "waveform: {type: csv, file: inflow.csv, period: 0.8}");
  const auto table = read_waveform(folder,
                                   "waveform: {type: table, times: [0, 0.1, 0.3, 0.8], "
                                   "values: [0, 1.0, 0.25, 0], period: 0.8}");
  ASSERT_EQ(csv.times.size(), 4u);
  for (double t : {0.0, 0.05, 0.1, 0.2, 0.55, 0.79, 0.85, 1.7, 12.345})
    EXPECT_DOUBLE_EQ(csv.factor(t), table.factor(t)) << "t = " << t;
  EXPECT_DOUBLE_EQ(csv.factor(0.2), 0.625);
  EXPECT_DOUBLE_EQ(csv.factor(0.8 + 0.05), 0.5);  // repeated with the period
}

TEST(TimeWaveform, BadCsvIsReportedWithFileAndLine) {
  const auto folder = test_folder("bad");
  std::ofstream(folder / "text.csv") << "time,factor\n0,0\n0.1,abc\n";
  std::ofstream(folder / "order.csv") << "0,0\n0.2,1\n0.1,2\n";
  std::ofstream(folder / "short.csv") << "time,factor\n0,1\n";
  std::ofstream(folder / "headers.csv") << "time,factor\nseconds,1\n0,1\n1,2\n";
  const auto path = [&](const std::string& file) { return (folder / file).string(); };

  auto message = error_of(folder, "waveform: {type: csv, file: text.csv}");
  EXPECT_NE(message.find(path("text.csv") + ":3"), std::string::npos) << message;
  message = error_of(folder, "waveform: {type: csv, file: order.csv}");
  EXPECT_NE(message.find(path("order.csv") + ":3"), std::string::npos) << message;
  EXPECT_NE(message.find("does not increase"), std::string::npos) << message;
  message = error_of(folder, "waveform: {type: csv, file: short.csv}");
  EXPECT_NE(message.find("at least 2 rows"), std::string::npos) << message;
  message = error_of(folder, "waveform: {type: csv, file: headers.csv}");
  EXPECT_NE(message.find(path("headers.csv") + ":2"), std::string::npos) << message;
  message = error_of(folder, "waveform: {type: csv, file: missing.csv}");
  EXPECT_NE(message.find("waveform.file"), std::string::npos) << message;
  EXPECT_NE(message.find("missing.csv"), std::string::npos) << message;
}

}  // namespace
