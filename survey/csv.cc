#include "survey/csv.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

std::string Trim(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = text.find_last_not_of(" \t\r");
  return text.substr(begin, end - begin + 1);
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    fields.push_back(Trim(line.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool HasUtf8ByteOrderMark(const std::string& text) {
  return text.compare(0, 3, "\xEF\xBB\xBF") == 0;
}

bool IsSkipped(const std::string& line) {
  const std::string trimmed = Trim(line);
  return trimmed.empty() || trimmed[0] == '#';
}

// Shortens a field for an error message so a garbage line does not flood
// the terminal.
std::string Quote(const std::string& field) {
  constexpr size_t kMaxShown = 40;
  if (field.size() <= kMaxShown) return "\"" + field + "\"";
  return "\"" + field.substr(0, kMaxShown) + "...\"";
}

}  // namespace

CsvTable CsvTable::Read(const std::string& path,
                        const std::string& display_name,
                        const std::vector<std::string>& required_columns) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(display_name, 0, "cannot open file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(display_name, 0, "read error");
  return Parse(text.str(), display_name, required_columns);
}

CsvTable CsvTable::Parse(const std::string& text,
                         const std::string& display_name,
                         const std::vector<std::string>& required_columns) {
  CsvTable table;
  table.display_name_ = display_name;
  if (text.find('\0') != std::string::npos) {
    throw InputError(display_name, 0, "binary data (NUL byte): not a CSV file");
  }
  // Spreadsheet exports start UTF-8 files with a byte-order mark; the
  // contract allows it and it is not part of the first column's name.
  std::istringstream in(HasUtf8ByteOrderMark(text) ? text.substr(3) : text);
  std::string line;
  int line_number = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_number;
    if (IsSkipped(line)) continue;
    if (line.find('"') != std::string::npos) {
      throw InputError(display_name, line_number,
                       "quoted fields are not supported");
    }
    std::vector<std::string> fields = SplitFields(line);
    if (!have_header) {
      table.header_ = std::move(fields);
      have_header = true;
      for (const std::string& column : required_columns) {
        if (table.ColumnIndex(column) < 0) {
          throw InputError(display_name, line_number,
                           "header lacks required column '" + column + "'");
        }
      }
      continue;
    }
    if (fields.size() < table.header_.size()) {
      throw InputError(display_name, line_number,
                       "truncated row: " + std::to_string(fields.size()) +
                           " fields, the header has " +
                           std::to_string(table.header_.size()));
    }
    if (fields.size() > table.header_.size()) {
      throw InputError(display_name, line_number,
                       "row has " + std::to_string(fields.size()) +
                           " fields, the header has " +
                           std::to_string(table.header_.size()));
    }
    table.rows_.push_back(Row{line_number, std::move(fields)});
  }
  if (!have_header) throw InputError(display_name, 0, "no header line");
  return table;
}

int CsvTable::ColumnIndex(const std::string& column) const {
  for (size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == column) return static_cast<int>(i);
  }
  return -1;
}

const std::string& CsvTable::Field(int row, const std::string& column) const {
  const int index = ColumnIndex(column);
  if (index < 0) Fail(row, "no column '" + column + "'");
  return rows_[row].fields[index];
}

double CsvTable::GetDouble(int row, const std::string& column) const {
  const std::string& field = Field(row, column);
  double value = 0.0;
  const char* begin = field.data();
  const char* end = begin + field.size();
  // from_chars does not accept a leading '+'.
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, value);
  if (field.empty() || result.ec != std::errc() || result.ptr != end) {
    if (result.ec == std::errc::result_out_of_range) {
      Fail(row,
           "column '" + column + "': " + Quote(field) + " is out of range");
    }
    Fail(row, "column '" + column + "': " + Quote(field) + " is not a number");
  }
  if (!std::isfinite(value)) {
    Fail(row, "column '" + column + "': " + Quote(field) + " is not finite");
  }
  return value;
}

int64_t CsvTable::GetInt(int row, const std::string& column) const {
  const std::string& field = Field(row, column);
  int64_t value = 0;
  const char* begin = field.data();
  const char* end = begin + field.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, value);
  if (field.empty() || result.ec != std::errc() || result.ptr != end) {
    Fail(row,
         "column '" + column + "': " + Quote(field) + " is not an integer");
  }
  return value;
}

const std::string& CsvTable::GetString(int row,
                                       const std::string& column) const {
  return Field(row, column);
}

void CsvTable::Fail(int row, const std::string& problem) const {
  throw InputError(display_name_, LineOf(row), problem);
}

std::string FormatDouble(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string FormatFixed(double value, int decimals) {
  char buffer[512];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value,
                                    std::chars_format::fixed, decimals);
  return std::string(buffer, result.ptr);
}

double ParseDouble(const std::string& text) {
  double value = 0.0;
  std::from_chars(text.data(), text.data() + text.size(), value);
  return value;
}

void CsvWriter::Comment(const std::string& text) {
  *out_ << "# " << text << '\n';
}

void CsvWriter::Header(const std::vector<std::string>& columns) {
  for (const std::string& column : columns) Add(column);
  EndRow();
}

void CsvWriter::Separator() {
  if (row_started_) *out_ << ',';
  row_started_ = true;
}

CsvWriter& CsvWriter::Add(double value) {
  Separator();
  *out_ << FormatDouble(value);
  return *this;
}

CsvWriter& CsvWriter::Add(int64_t value) {
  Separator();
  *out_ << value;
  return *this;
}

CsvWriter& CsvWriter::Add(const std::string& value) {
  Separator();
  // The format has no quoting: keep fields parseable.
  for (char c : value) *out_ << (c == ',' || c == '\n' || c == '\r' ? ';' : c);
  return *this;
}

CsvWriter& CsvWriter::AddFixed(double value, int decimals) {
  Separator();
  *out_ << FormatFixed(value, decimals);
  return *this;
}

void CsvWriter::EndRow() {
  *out_ << '\n';
  row_started_ = false;
}

}  // namespace zebrageo
