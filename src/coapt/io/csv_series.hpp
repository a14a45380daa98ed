#pragma once
/// @file csv_series.hpp
/// A CSV time series (one row per step, e.g. forces, volumes, iteration counts), written by
/// rank 0 and flushed after every row so that a run that crashes keeps what it wrote.
///
///   CsvSeries csv(comm, out / "forces.csv");
///   csv.add("time", t);
///   csv.add("drag", drag);
///   csv.end_row();  // first row: header "time,drag", then the values
///
/// Values are printed with %.17g (they read back to the same double); NaN and infinities
/// are written as nan, inf and -inf (which Python's float() and numpy read). Column names
/// containing a comma, a double quote or a line break are quoted as RFC 4180 says.

#include <mpi.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace coapt::io {

class CsvSeries {
 public:
  /// Creates (truncates) the file on rank 0, creating its parent directories if missing.
  /// Collective on `comm`: every rank throws the same coapt::Error if the file cannot be
  /// opened. The communicator must outlive the series.
  explicit CsvSeries(std::filesystem::path path, MPI_Comm comm = MPI_COMM_WORLD);
  CsvSeries(MPI_Comm comm, std::filesystem::path path) : CsvSeries(std::move(path), comm) {}
  CsvSeries(const CsvSeries&) = delete;
  CsvSeries& operator=(const CsvSeries&) = delete;
  CsvSeries(CsvSeries&&) noexcept = default;
  CsvSeries& operator=(CsvSeries&&) noexcept = default;
  ~CsvSeries();

  /// Sets `column` of the current row. Local (no communication); rank 0's values are the
  /// ones written. Throws InternalError if the column was already set in this row.
  void add(std::string column, double value);

  /// Ends the current row: on the first call, writes the header (the columns in the order
  /// they were first added) and the row; later, the row, whose columns must be the same
  /// set as the header's (in any order of add; written in the header's order), otherwise
  /// InternalError naming the missing and extra columns (the row is then discarded).
  /// Collective on the communicator (every rank calls it for every row, with the same
  /// columns); a write failure on rank 0 throws the same coapt::Error on every rank.
  void end_row();

  /// Rows written so far (not counting the header).
  int n_rows() const { return n_rows_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* file) const { std::fclose(file); }
  };

  std::filesystem::path path_;
  MPI_Comm comm_;
  int rank_ = 0;
  std::unique_ptr<std::FILE, FileCloser> file_;  ///< rank 0 only
  std::vector<std::string> header_;              ///< empty until the first row
  std::vector<std::pair<std::string, double>> row_;
  int n_rows_ = 0;
};

}  // namespace coapt::io
