#pragma once
// Numeric CSV: a streaming writer for per-step statistics and a reader for tests and tools.
// Numbers are written in the shortest form that parses back to the same double; integral values
// are written without a decimal point so counts and step numbers read naturally.
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

namespace msim::io {

// Writes `columns` as header, then one line per addRow(). Rows go to a temporary file as they are
// added; commit() renames it to the target. A writer destroyed without commit() (an exception
// unwound past it) removes the temporary, so a CSV only ever appears complete.
class CsvWriter {
 public:
  // Column names must be non-empty and free of commas, quotes and line breaks
  // (std::invalid_argument otherwise). Throws std::runtime_error if the file cannot be created.
  CsvWriter(std::filesystem::path target, std::vector<std::string> columns);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  const std::vector<std::string>& columns() const { return columns_; }
  // One value per column, std::invalid_argument otherwise.
  void addRow(std::span<const double> values);
  void addRow(std::initializer_list<double> values) { addRow(std::span<const double>(values.begin(), values.size())); }
  // Flushes, closes and renames into place; further addRow() calls throw std::logic_error.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path tmp_;
  std::vector<std::string> columns_;
  std::ofstream out_;
  bool committed_ = false;
};

// Formats v as the CSV writer does: integral values (|v| < 2^53) without decimals, others in the
// shortest round-trip form ("nan", "inf", "-inf" for non-finite values).
std::string formatCsvNumber(double v);

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  // Index of the named column; InputError if absent.
  std::size_t columnIndex(const std::string& name) const;
  std::vector<double> column(const std::string& name) const;
};

// Reads a numeric CSV with a header line. Blank lines are skipped. InputError (naming file and
// line) for a missing file, a non-numeric field or a row with the wrong number of fields.
CsvTable readCsv(const std::filesystem::path& path);

}  // namespace msim::io
