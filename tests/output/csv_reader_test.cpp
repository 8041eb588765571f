// The one CSV reader (feeddrive/csv/reader.hpp) of waypoints, open-loop tables and fit data:
// what it accepts, its one-line errors naming file:line:column and the value, and its bounds
// (binary files, /dev/zero, long lines, too many rows).
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "feeddrive/csv/reader.hpp"

namespace feeddrive::csv {
namespace {

std::string write_temp(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + "feeddrive_csv_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
  return path;
}

// Columns t and x, t increasing, two rows at least: the waypoints' options.
Options tx() {
  Options o;
  o.columns = {{{"t"}}, {{"x"}}};
  o.increasing = 0;
  o.limits.min_rows = 2;
  return o;
}

std::string error_of(const std::string& path, const Options& o = tx()) {
  try {
    read_file(path, o);
  } catch (const CsvError& e) {
    return e.what();
  }
  return "";
}

TEST(CsvReader, ColumnsInAnyOrderCommentsBlanksCrlfQuotesAndByteOrderMark) {
  const std::string path = write_temp("ok.csv",
                                      "\xEF\xBB\xBF# a move in three points\n"
                                      "\n"
                                      "x, label ,\"t\"\r\n"  // CRLF, spaces, a quoted name, an extra column
                                      "0.0,start,0\n"
                                      "   # indented comment\n"
                                      "+1.5e-2,mid,0.5\r\n"
                                      "\n"
                                      "-0.25,end,1.25\n");
  const Table t = read_file(path, tx());
  ASSERT_EQ(t.rows(), 3u);
  EXPECT_EQ(t.values[0], (std::vector<double>{0.0, 0.5, 1.25}));
  EXPECT_EQ(t.values[1], (std::vector<double>{0.0, 0.015, -0.25}));
  EXPECT_EQ(t.lines, (std::vector<long>{4, 6, 8}));
}

// A logger's separator after the last field of every line (issue 20's review: "t<tab>x<tab>F<tab>"
// was refused as an empty column name): no column; rows may end with it or not. An empty name
// inside the header stays an error (EachErrorIsOneLine...), and so does a row with a value there.
TEST(CsvReader, ASeparatorAfterTheLastFieldIsNoColumn) {
  Options o = tx();
  o.separator = '\t';
  const Table t = read_file(write_temp("trailing_tab.csv", "t\tx\t\n0\t1\t\n0.5\t2\n1\t3\t\n"), o);
  ASSERT_EQ(t.rows(), 3u);
  EXPECT_EQ(t.values[0], (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(t.values[1], (std::vector<double>{1.0, 2.0, 3.0}));
  try {
    read_file(write_temp("trailing_value.csv", "t,x,\n0,1,\n1,2,7\n"), tx());
    ADD_FAILURE() << "a value under no column must be refused";
  } catch (const CsvError& e) {
    EXPECT_NE(std::string(e.what()).find(":3: 3 fields, the header has 2"), std::string::npos) << e.what();
  }
}

TEST(CsvReader, AlternativeAndOptionalColumns) {
  Options o;
  o.columns = {{{"t"}}, {{"force_N", "u"}}, {{"xd"}, false}};
  const Table a = parse("t,u\n0,1\n", "a", o);
  EXPECT_EQ(a.used[1], "u");
  EXPECT_FALSE(a.has(2));
  const Table b = parse("u,force_N,t,xd\n1,2,0,3\n", "b", o);
  EXPECT_EQ(b.used[1], "force_N");  // the first alternative the header has
  EXPECT_EQ(b.values[1][0], 2.0);
  EXPECT_EQ(b.values[2][0], 3.0);
}

TEST(CsvReader, EachErrorIsOneLineNamingFileLineColumnAndValue) {
  struct Case {
    const char* name;
    const char* content;
    const char* expected;  // after "<path>"
  };
  const Case cases[] = {
      {"abc.csv", "t,x\n0,0\n# c\n0.1,0.01\n\n0.3,abc\n", ":6:5: column 'x': not a number: 'abc'"},
      {"missing_x.csv", "t,y\n0,1\n1,2\n", ":1: missing column 'x' in the header 't,y'"},
      {"missing_t.csv", "# c\ntime,x\n0,1\n", ":2: missing column 't' in the header 'time,x'"},
      {"semicolons.csv", "t;x\n0;1\n",
       ":1: missing column 't' in the header 't;x'; columns must be separated by commas"},
      {"duplicate.csv", "t,x,t\n0,1,0\n", ":1:5: duplicate column 't' in the header"},
      {"empty_name.csv", "t,,x\n0,1,0\n", ":1:3: empty column name (column 2 of the header)"},
      {"order.csv", "t,x\n0.1,0\n0.3,1\n\n0.2,2\n",
       ":5:1: column 't': 0.2 is not greater than the previous t = 0.3 (line 3)"},
      {"equal.csv", "t,x\n0.1,0\n0.1,1\n", ":3:1: column 't': 0.1 is not greater than the previous t = 0.1 (line 2)"},
      {"nan.csv", "t,x\n0,0\n1,nan\n", ":3:3: column 'x': not a finite number: 'nan'"},
      {"inf.csv", "t,x\n0,0\n-inf,1\n", ":3:1: column 't': not a finite number: '-inf'"},
      {"huge.csv", "t,x\n0,0\n1,1e999\n", ":3:3: column 'x': out of the range of a double: '1e999'"},
      {"short_row.csv", "t,x\n0,0\n1\n", ":3: 1 fields, the header has 2 (truncated or extra field?)"},
      {"long_row.csv", "t,x\n0,0\n1,2,3\n", ":3: 3 fields, the header has 2 (truncated or extra field?)"},
      {"empty_field.csv", "t,x\n0,0\n ,1\n", ":3:1: column 't': missing value"},
      {"trailing.csv", "t,x\n0,0\n1,2.5m\n", ":3:3: column 'x': not a number: '2.5m'"},
      {"bom_column.csv", "\xEF\xBB\xBFt,x\n0,0\n1,y\n", ":3:3: column 'x': not a number: 'y'"},
      {"non_ascii.csv", "t,x\n0,0\n1,\xC3\xA9\xFF\n", ":3:3: column 'x': not a number: '\\xC3\\xA9\\xFF'"},
      {"one_row.csv", "t,x\n0,0\n", ":2: need at least 2 data rows, found 1 (end of file)"},
      {"no_rows.csv", "t,x\n# nothing\n", ":2: need at least 2 data rows, found 0 (end of file)"},
      {"empty.csv", "", ": no header line (expected the columns t, x)"},
  };
  for (const Case& c : cases) {
    const std::string path = write_temp(c.name, c.content);
    const std::string message = error_of(path);
    EXPECT_EQ(message, path + c.expected) << c.name;
    EXPECT_EQ(message.find('\n'), std::string::npos) << c.name;
  }
}

// A logger's decimal comma in a ';'-separated file read without decimal_comma: the value is named
// with the hint, and the caller's option when it gives one (issue 20's review: "not a number:
// '0,0'" alone). A value that is no number either way gets no hint.
TEST(CsvReader, ADecimalCommaNotAskedForIsHinted) {
  Options o = tx();
  o.separator = ';';
  const std::string path = write_temp("decimal_comma.csv", "t;x\n0;0\n1;0,25\n");
  EXPECT_EQ(error_of(path, o), path +
                                   ":3:3: column 'x': not a number: '0,25'; a decimal comma? (it is read only "
                                   "when asked for)");
  o.decimal_comma_option = "--decimal-comma";
  EXPECT_EQ(error_of(path, o), path +
                                   ":3:3: column 'x': not a number: '0,25'; a decimal comma? (give it with "
                                   "--decimal-comma)");
  const std::string other = write_temp("comma_text.csv", "t;x\n0;0\n1;a,b\n");
  EXPECT_EQ(error_of(other, o), other + ":3:3: column 'x': not a number: 'a,b'");
  o.decimal_comma = true;
  EXPECT_EQ(error_of(path, o), "");
}

// A column asked for by an index beyond the header names the range (issue 20's review: "missing
// column '9'" alone).
TEST(CsvReader, AColumnIndexBeyondTheHeaderNamesTheRange) {
  Options o;
  o.columns = {{{"t"}}, {{"9"}}};
  o.columns_by_index = true;
  o.limits.min_rows = 2;
  const std::string path = write_temp("index.csv", "t,a,b\n0,0,0\n1,1,1\n");
  EXPECT_EQ(error_of(path, o), path + ":1: missing column '9' in the header 't,a,b'; a column index is 1 to 3 here");
  o.columns = {{{"t"}}, {{"3"}}};
  EXPECT_EQ(error_of(path, o), "");
}

TEST(CsvReader, FilesThatCannotBeRead) {
  const std::string missing = ::testing::TempDir() + "feeddrive_csv_does_not_exist.csv";
  EXPECT_EQ(error_of(missing), missing + ": cannot open the file: No such file or directory");
  EXPECT_EQ(error_of(::testing::TempDir()).find(": is a folder, not a data file") != std::string::npos, true);
}

// A binary file never prints its bytes: one line with an escaped excerpt of at most 24 bytes.
TEST(CsvReader, BinaryFilesGetOneEscapedLine) {
  std::string bin = "t,x\n0,0\n";
  for (int i = 0; i < 4000; ++i) bin += static_cast<char>((i * 37) & 0xff);
  const std::string path = write_temp("binary.bin", bin);
  const std::string m = error_of(path);
  EXPECT_NE(m.find(path + ":3:"), std::string::npos) << m;
  EXPECT_NE(m.find("not a text file: byte 0x00"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos);
  for (char c : m) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "raw byte " << int(static_cast<unsigned char>(c));
  EXPECT_LT(m.size(), path.size() + 120);
}

// /dev/zero: endless NUL bytes. A device is refused before it is read, with one line (a FIFO,
// which would block open(), the same way).
TEST(CsvReader, DevZeroEndsAtOnceWithOneLine) {
  EXPECT_EQ(error_of("/dev/zero"), "/dev/zero: is a device, not a regular file");
}

TEST(CsvReader, LineFileAndRowLimits) {
  Options o = tx();
  o.limits.max_line_bytes = 1000;
  const std::string long_line = write_temp("long_line.csv", "t,x\n0," + std::string(5000, '1') + "\n");
  EXPECT_EQ(error_of(long_line, o), long_line + ":2: line longer than 1000 bytes (not a CSV file?)");
  o = tx();
  o.limits.max_rows = 3;
  const std::string rows = write_temp("rows.csv", "t,x\n0,0\n1,1\n2,2\n3,3\n");
  EXPECT_EQ(error_of(rows, o), rows + ":5: more than 3 data rows (the reader's limit)");
  o = tx();
  o.limits.max_file_bytes = 10;
  EXPECT_EQ(error_of(rows, o), rows + ": 20 bytes, larger than the reader's limit of 10 bytes");
}

}  // namespace
}  // namespace feeddrive::csv
