#include "survey/csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

std::string MessageOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

TEST(CsvTable, SkipsCommentsAndBlankLinesAndKeepsFileLineNumbers) {
  const CsvTable table =
      CsvTable::Parse("# a comment\n\n  # indented comment\na,b\n1,2\n\n3,4\n",
                      "t.csv", {"a", "b"});
  ASSERT_EQ(table.NumRows(), 2);
  EXPECT_EQ(table.LineOf(0), 5);
  EXPECT_EQ(table.LineOf(1), 7);
  EXPECT_EQ(table.GetInt(1, "b"), 4);
}

TEST(CsvTable, IgnoresALeadingUtf8ByteOrderMark) {
  const CsvTable table =
      CsvTable::Parse("\xEF\xBB\xBFtime,a\n1,2\n", "t.csv", {"time", "a"});
  ASSERT_EQ(table.NumRows(), 1);
  EXPECT_EQ(table.LineOf(0), 2);
  EXPECT_DOUBLE_EQ(table.GetDouble(0, "time"), 1.0);
  // Before comments too, and only at the very start of the file.
  EXPECT_EQ(CsvTable::Parse("\xEF\xBB\xBF# c\ntime\n1\n", "t.csv", {"time"})
                .NumRows(),
            1);
  EXPECT_THAT(MessageOf([] {
                CsvTable::Parse(
                    "time\n\xEF\xBB\xBF"
                    "1\n",
                    "t.csv", {"time"})
                    .GetDouble(0, "time");
              }),
              HasSubstr("t.csv:2: column 'time'"));
}

TEST(CsvTable, FindsColumnsByNameAndAllowsExtraColumns) {
  const CsvTable table =
      CsvTable::Parse("b,extra,a\n2.5,x,-1e3\n", "t.csv", {"a", "b"});
  EXPECT_DOUBLE_EQ(table.GetDouble(0, "a"), -1000.0);
  EXPECT_DOUBLE_EQ(table.GetDouble(0, "b"), 2.5);
  EXPECT_EQ(table.GetString(0, "extra"), "x");
}

TEST(CsvTable, RejectsMissingRequiredColumnNamingHeaderLine) {
  EXPECT_THAT(MessageOf([] {
                CsvTable::Parse("#c\na,c\n", "t.csv", {"a", "b"});
              }),
              HasSubstr("t.csv:2: header lacks required column 'b'"));
}

TEST(CsvTable, RejectsTruncatedRowWithItsLine) {
  EXPECT_THAT(MessageOf([] {
                CsvTable::Parse("a,b\n1,2\n3\n", "t.csv", {"a", "b"});
              }),
              HasSubstr("t.csv:3: truncated row: 1 fields, the header has 2"));
}

TEST(CsvTable, RejectsNonNumbersNanAndInfinityNamingColumn) {
  const CsvTable table =
      CsvTable::Parse("a,b,c\nabc,nan,inf\n", "t.csv", {"a", "b", "c"});
  EXPECT_THAT(MessageOf([&] { table.GetDouble(0, "a"); }),
              HasSubstr("t.csv:2: column 'a': \"abc\" is not a number"));
  EXPECT_THAT(MessageOf([&] { table.GetDouble(0, "b"); }),
              HasSubstr("t.csv:2: column 'b': \"nan\" is not finite"));
  EXPECT_THAT(MessageOf([&] { table.GetDouble(0, "c"); }),
              HasSubstr("t.csv:2: column 'c': \"inf\" is not finite"));
}

TEST(CsvTable, RejectsTrailingGarbageAndFractionalIntegers) {
  const CsvTable table =
      CsvTable::Parse("a,b\n1.5x,2.5\n", "t.csv", {"a", "b"});
  EXPECT_THAT(MessageOf([&] { table.GetDouble(0, "a"); }),
              HasSubstr("is not a number"));
  EXPECT_THAT(MessageOf([&] { table.GetInt(0, "b"); }),
              HasSubstr("t.csv:2: column 'b': \"2.5\" is not an integer"));
}

TEST(CsvTable, RejectsEmptyFileAndBinaryData) {
  EXPECT_THAT(MessageOf([] { CsvTable::Parse("# only\n", "t.csv", {}); }),
              HasSubstr("t.csv: no header line"));
  EXPECT_THAT(MessageOf([] {
                CsvTable::Parse(std::string("a\n\0\x01", 4), "t.csv", {});
              }),
              HasSubstr("binary data"));
}

TEST(CsvTable, RejectsMissingFile) {
  EXPECT_THAT(MessageOf([] {
                CsvTable::Read("/nonexistent/zebrageo.csv", "x.csv", {});
              }),
              HasSubstr("x.csv: cannot open file"));
}

TEST(FormatDouble, RoundTripsExactly) {
  for (double value : {0.1, 1.0 / 3.0, 49.894112345678901, -122.4723,
                       404106.397000, 1e-300, 6.02e23}) {
    EXPECT_EQ(std::stod(FormatDouble(value)), value) << FormatDouble(value);
  }
}

TEST(CsvWriter, WritesRowsThatReadBack) {
  std::ostringstream out;
  CsvWriter csv(&out);
  csv.Comment("made by a test");
  csv.Header({"id", "name", "value"});
  csv.Add(int64_t{7}).Add("a,b").Add(1.0 / 3.0);
  csv.EndRow();
  const CsvTable table = CsvTable::Parse(out.str(), "w.csv", {"id", "value"});
  EXPECT_EQ(table.GetInt(0, "id"), 7);
  EXPECT_EQ(table.GetString(0, "name"), "a;b");
  EXPECT_EQ(table.GetDouble(0, "value"), 1.0 / 3.0);
}

}  // namespace
}  // namespace zebrageo
