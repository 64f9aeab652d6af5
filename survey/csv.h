// The one CSV reader and writer of the project.
//
// Reading: a leading UTF-8 byte-order mark is ignored (spreadsheet exports
// write one; SURVEY_FORMAT.md allows it); lines starting with '#' (after
// optional spaces) and blank lines are skipped; the first other line is the
// header. Columns are found by name, so extra columns are allowed and ignored.
// Every accessor that fails throws InputError with the file, the line number in
// the file and the column, e.g.
//   trajectory.csv:213: column 'heading': "abc" is not a number
// Fields are split on ',' and trimmed; quoting is not used by the survey
// format and a '"' in a field is rejected.
//
// Writing: CsvWriter formats doubles in the shortest form that reads back to
// the same double (std::to_chars), so nothing is lost in a round trip.
#ifndef ZEBRAGEO_SURVEY_CSV_H_
#define ZEBRAGEO_SURVEY_CSV_H_

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace zebrageo {

class CsvTable {
 public:
  // Reads `path`; `display_name` is the name used in error messages (the
  // path relative to the survey folder, as the user knows it). Throws
  // InputError when the file cannot be read, has no header, a required column
  // is missing, or a row has fewer fields than the header.
  static CsvTable Read(const std::string& path, const std::string& display_name,
                       const std::vector<std::string>& required_columns);
  // Same, from text in memory (fuzzing, tests).
  static CsvTable Parse(const std::string& text,
                        const std::string& display_name,
                        const std::vector<std::string>& required_columns);

  int NumRows() const { return static_cast<int>(rows_.size()); }
  // Index of `column` in the header, or -1.
  int ColumnIndex(const std::string& column) const;
  bool HasColumn(const std::string& column) const {
    return ColumnIndex(column) >= 0;
  }
  // Line number (1-based, in the file) of data row `row`.
  int LineOf(int row) const { return rows_[row].line; }

  // Typed access by column name. GetDouble rejects NaN and infinities.
  double GetDouble(int row, const std::string& column) const;
  int64_t GetInt(int row, const std::string& column) const;
  const std::string& GetString(int row, const std::string& column) const;

  const std::string& display_name() const { return display_name_; }

  // Throws InputError("<display_name>:<line of row>: <problem>").
  [[noreturn]] void Fail(int row, const std::string& problem) const;

 private:
  struct Row {
    int line = 0;
    std::vector<std::string> fields;
  };
  const std::string& Field(int row, const std::string& column) const;

  std::string display_name_;
  std::vector<std::string> header_;
  std::vector<Row> rows_;
};

// Writes one CSV line at a time to a stream.
class CsvWriter {
 public:
  explicit CsvWriter(std::ostream* out) : out_(out) {}

  void Comment(const std::string& text);  // "# text"
  void Header(const std::vector<std::string>& columns);

  CsvWriter& Add(double value);
  CsvWriter& Add(int64_t value);
  CsvWriter& Add(int value) { return Add(static_cast<int64_t>(value)); }
  CsvWriter& Add(const std::string& value);
  CsvWriter& Add(const char* value) { return Add(std::string(value)); }
  // Writes a double with a fixed number of decimals (angles, for readability).
  CsvWriter& AddFixed(double value, int decimals);
  void EndRow();

 private:
  void Separator();

  std::ostream* out_;
  bool row_started_ = false;
};

// Shortest decimal text that reads back to exactly `value`.
std::string FormatDouble(double value);
// `value` with `decimals` decimals (printf's %.*f): for a person, and the
// fixed-point columns of the results files.
std::string FormatFixed(double value, int decimals);
// The double a decimal text denotes (the CSV reader's parse): 0 for text
// that is not one.
double ParseDouble(const std::string& text);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_CSV_H_
