#include "coapt/io/csv_series.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <system_error>

#include "coapt/core/error.hpp"

namespace coapt::io {

namespace {

/// Rank 0's `problem` (empty: none), thrown as coapt::Error on every rank.
void throw_if_root_failed(MPI_Comm comm, int rank, const std::string& problem) {
  long long size = rank == 0 ? static_cast<long long>(problem.size()) : 0;
  MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, comm);
  if (size == 0) return;
  std::string message = rank == 0 ? problem : std::string(static_cast<std::size_t>(size), '\0');
  MPI_Bcast(message.data(), static_cast<int>(size), MPI_CHAR, 0, comm);
  throw Error(message);
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

std::string csv_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

}  // namespace

CsvSeries::CsvSeries(std::filesystem::path path, MPI_Comm comm)
    : path_(std::move(path)), comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  std::string problem;
  if (rank_ == 0) {
    if (path_.has_parent_path()) {
      std::error_code ec;
      std::filesystem::create_directories(path_.parent_path(), ec);
      if (ec)
        problem = fmt::format("cannot create the directory {}: {}", path_.parent_path().string(),
                              ec.message());
    }
    if (problem.empty()) {
      file_.reset(std::fopen(path_.c_str(), "w"));
      if (!file_)
        problem =
            fmt::format("cannot open {} for writing: {}", path_.string(), std::strerror(errno));
    }
  }
  throw_if_root_failed(comm_, rank_, problem);
}

CsvSeries::~CsvSeries() = default;

void CsvSeries::add(std::string column, double value) {
  for (const auto& entry : row_)
    if (entry.first == column)
      throw InternalError(
          fmt::format("{}: column '{}' set twice in row {}", path_.string(), column, n_rows_ + 1));
  row_.emplace_back(std::move(column), value);
}

void CsvSeries::end_row() {
  std::vector<std::pair<std::string, double>> row;
  row.swap(row_);  // the row is consumed whatever happens
  if (row.empty())
    throw InternalError(fmt::format("{}: end_row() on an empty row", path_.string()));

  const bool first = header_.empty();
  std::vector<double> values;
  if (first) {
    for (const auto& entry : row) {
      header_.push_back(entry.first);
      values.push_back(entry.second);
    }
  } else {
    std::vector<std::string> missing, extra;
    values.assign(header_.size(), 0.0);
    for (std::size_t i = 0; i < header_.size(); ++i) {
      const auto it = std::find_if(row.begin(), row.end(),
                                   [&](const auto& entry) { return entry.first == header_[i]; });
      if (it == row.end())
        missing.push_back(header_[i]);
      else
        values[i] = it->second;
    }
    for (const auto& entry : row)
      if (std::find(header_.begin(), header_.end(), entry.first) == header_.end())
        extra.push_back(entry.first);
    if (!missing.empty() || !extra.empty())
      throw InternalError(fmt::format(
          "{}: row {} does not have the header's columns (missing: {}; not in the header: {})",
          path_.string(), n_rows_ + 1,
          missing.empty() ? "none" : fmt::format("{}", fmt::join(missing, ", ")),
          extra.empty() ? "none" : fmt::format("{}", fmt::join(extra, ", "))));
  }

  std::string problem;
  if (rank_ == 0) {
    std::string text;
    if (first) {
      for (std::size_t i = 0; i < header_.size(); ++i) {
        if (i > 0) text += ',';
        text += csv_field(header_[i]);
      }
      text += '\n';
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i > 0) text += ',';
      text += csv_number(values[i]);
    }
    text += '\n';
    errno = 0;
    if (!file_ || std::fwrite(text.data(), 1, text.size(), file_.get()) != text.size() ||
        std::fflush(file_.get()) != 0)
      problem = fmt::format("cannot write to {}: {}", path_.string(),
                            errno ? std::strerror(errno) : "file not open");
  }
  throw_if_root_failed(comm_, rank_, problem);
  ++n_rows_;
}

}  // namespace coapt::io
