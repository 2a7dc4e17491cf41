#include "msim/io/csv.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <system_error>

#include "msim/core/error.hpp"
#include "msim/io/atomic_file.hpp"

namespace msim::io {

namespace {

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

}  // namespace

std::string formatCsvNumber(double v) {
  char buf[64];
  constexpr double kExactIntegerLimit = 9007199254740992.0;  // 2^53: larger doubles skip integers
  std::to_chars_result r;
  if (std::isfinite(v) && v == std::trunc(v) && std::abs(v) < kExactIntegerLimit)
    r = std::to_chars(buf, buf + sizeof buf, static_cast<long long>(v));
  else
    r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

CsvWriter::CsvWriter(std::filesystem::path target, std::vector<std::string> columns)
    : target_(std::move(target)), tmp_(temporaryPathFor(target_)), columns_(std::move(columns)) {
  if (columns_.empty()) throw std::invalid_argument("CsvWriter: no columns for " + target_.string());
  for (const auto& c : columns_)
    if (c.empty() || c.find_first_of(",\"\r\n") != std::string::npos)
      throw std::invalid_argument("CsvWriter: bad column name '" + c + "' for " + target_.string());
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error("cannot create " + tmp_.string());
  for (std::size_t i = 0; i < columns_.size(); ++i) out_ << (i ? "," : "") << columns_[i];
  out_ << '\n';
}

CsvWriter::~CsvWriter() {
  if (committed_) return;
  out_.close();
  std::error_code ignored;
  std::filesystem::remove(tmp_, ignored);
}

void CsvWriter::addRow(std::span<const double> values) {
  if (committed_) throw std::logic_error("CsvWriter: addRow after commit for " + target_.string());
  if (values.size() != columns_.size())
    throw std::invalid_argument("CsvWriter: row of " + std::to_string(values.size()) + " values for " +
                                std::to_string(columns_.size()) + " columns in " + target_.string());
  for (std::size_t i = 0; i < values.size(); ++i) out_ << (i ? "," : "") << formatCsvNumber(values[i]);
  out_ << '\n';
}

void CsvWriter::commit() {
  if (committed_) return;
  out_.close();
  if (!out_) throw std::runtime_error("error writing " + tmp_.string());
  std::filesystem::rename(tmp_, target_);
  committed_ = true;
}

std::size_t CsvTable::columnIndex(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  throw InputError("CSV has no column '" + name + "'");
}

std::vector<double> CsvTable::column(const std::string& name) const {
  const std::size_t c = columnIndex(name);
  std::vector<double> values;
  values.reserve(rows.size());
  for (const auto& row : rows) values.push_back(row[c]);
  return values;
}

CsvTable readCsv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open CSV file");
  CsvTable table;
  std::string line;
  int lineNo = 0;
  bool haveHeader = false;
  while (std::getline(in, line)) {
    ++lineNo;
    if (trim(line).empty()) continue;
    const auto fields = splitFields(line);
    const std::string where = path.string() + ":" + std::to_string(lineNo) + ": ";
    if (!haveHeader) {
      for (auto f : fields) {
        if (f.empty()) throw InputError(where + "empty column name in CSV header");
        table.columns.emplace_back(f);
      }
      haveHeader = true;
      continue;
    }
    if (fields.size() != table.columns.size())
      throw InputError(where + "expected " + std::to_string(table.columns.size()) + " fields, got " +
                       std::to_string(fields.size()));
    std::vector<double> row(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const char* last = fields[i].data() + fields[i].size();
      const auto [end, ec] = std::from_chars(fields[i].data(), last, row[i]);
      if (ec != std::errc() || end != last || fields[i].empty())
        throw InputError(where + "expected a number in column '" + table.columns[i] + "', got '" +
                         std::string(fields[i]) + "'");
    }
    table.rows.push_back(std::move(row));
  }
  if (!haveHeader) throw InputError(path.string() + ": empty CSV file, expected a header line");
  return table;
}

}  // namespace msim::io
