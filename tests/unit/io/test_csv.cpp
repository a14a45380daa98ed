#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/io/csv_series.hpp"

namespace {

using coapt::io::CsvSeries;

std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("coapt_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, separator)) out.push_back(item);
  return out;
}

TEST(CsvSeries, WritesHeaderThenRowsWithFullPrecision) {
  const auto dir = scratch_dir("csv");
  const auto path = dir / "sub" / "forces.csv";  // parent directories are created
  const std::vector<double> times = {0.0, 0.1, 1.0 / 3.0};
  const std::vector<double> drags = {1e-300, -2.5e300, 4.9406564584124654e-324};
  {
    CsvSeries csv(MPI_COMM_SELF, path);
    for (std::size_t i = 0; i < times.size(); ++i) {
      if (i == 1) {  // columns may be added in another order after the first row
        csv.add("drag", drags[i]);
        csv.add("time", times[i]);
      } else {
        csv.add("time", times[i]);
        csv.add("drag", drags[i]);
      }
      csv.end_row();
      // Flushed at every row: the file holds the row before the series is closed.
      const auto lines = split(read_file(path), '\n');
      ASSERT_EQ(lines.size(), i + 2);
    }
    EXPECT_EQ(csv.n_rows(), 3);
  }
  const auto lines = split(read_file(path), '\n');
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "time,drag");
  EXPECT_EQ(lines[1], "0,1e-300");  // %.17g, as Python's '%.17g' % x prints them
  EXPECT_EQ(lines[2], "0.10000000000000001,-2.5000000000000001e+300");
  EXPECT_EQ(lines[3], "0.33333333333333331,4.9406564584124654e-324");
  for (std::size_t i = 0; i < times.size(); ++i) {
    const auto cells = split(lines[i + 1], ',');
    ASSERT_EQ(cells.size(), 2u);
    EXPECT_EQ(std::strtod(cells[0].c_str(), nullptr), times[i]);  // exact round trip
    EXPECT_EQ(std::strtod(cells[1].c_str(), nullptr), drags[i]);
  }
  std::filesystem::remove_all(dir);
}

TEST(CsvSeries, NonFiniteValuesAndQuotedNames) {
  const auto dir = scratch_dir("csv_nonfinite");
  const auto path = dir / "x.csv";
  {
    CsvSeries csv(path, MPI_COMM_SELF);
    csv.add("a,b", std::numeric_limits<double>::quiet_NaN());
    csv.add("say \"hi\"", std::numeric_limits<double>::infinity());
    csv.add("c", -std::numeric_limits<double>::infinity());
    csv.end_row();
  }
  EXPECT_EQ(read_file(path), "\"a,b\",\"say \"\"hi\"\"\",c\nnan,inf,-inf\n");
  std::filesystem::remove_all(dir);
}

TEST(CsvSeries, RowsMustKeepTheHeadersColumns) {
  const auto dir = scratch_dir("csv_columns");
  const auto path = dir / "x.csv";
  CsvSeries csv(MPI_COMM_SELF, path);
  csv.add("time", 0.0);
  csv.add("drag", 1.0);
  csv.end_row();

  csv.add("time", 1.0);
  try {
    csv.end_row();
    FAIL() << "no exception for a missing column";
  } catch (const coapt::InternalError& e) {
    EXPECT_NE(std::string(e.what()).find("missing: drag"), std::string::npos) << e.what();
  }
  csv.add("time", 1.0);
  csv.add("drag", 1.0);
  csv.add("lift", 1.0);
  try {
    csv.end_row();
    FAIL() << "no exception for an extra column";
  } catch (const coapt::InternalError& e) {
    EXPECT_NE(std::string(e.what()).find("not in the header: lift"), std::string::npos) << e.what();
  }
  csv.add("time", 2.0);
  EXPECT_THROW(csv.add("time", 3.0), coapt::InternalError);  // twice in one row
  csv.add("drag", 2.0);
  csv.end_row();  // the failed rows were discarded; this one is fine
  EXPECT_THROW(csv.end_row(), coapt::InternalError);  // empty row
  EXPECT_EQ(csv.n_rows(), 2);
  EXPECT_EQ(read_file(path), "time,drag\n0,1\n2,2\n");
  std::filesystem::remove_all(dir);
}

TEST(CsvSeries, UnwritablePathThrows) {
  EXPECT_THROW(CsvSeries("/proc/coapt-no-such-dir/x.csv", MPI_COMM_SELF), coapt::Error);
}

}  // namespace
