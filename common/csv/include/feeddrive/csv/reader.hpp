#pragma once
// The one CSV reader of feeddrive: waypoints (reference.file), open-loop force or command
// tables (controller.file) and feeddrive-fit's measured data all go through it, so they accept
// the same files and fail with the same one-line messages.
//
// Format: UTF-8 text (a byte-order mark is skipped), lines ending in LF or CRLF. Blank lines and
// lines whose first non-blank character is '#' are skipped. The first other line is the header:
// column names separated by Options::separator (a comma by default) (spaces around them and double quotes are dropped;
// no name may be empty or appear twice). Every data row has exactly as many fields as the header. The columns asked for
// are read as numbers by std::from_chars (locale-independent; a leading '+' is accepted) and must be finite; other
// columns are ignored.
//
// Every error is a CsvError (std::invalid_argument), one line:
//   FILE: ...                    (the file as a whole: cannot open, too large, no header)
//   FILE:LINE: ...               (a line: too long, wrong number of fields, binary)
//   FILE:LINE:COL: column 'x': not a number: '2.5m'     (COL: 1-based byte column of the field)
// Values are shown escaped and cut (at most 40 bytes; control and non-ASCII bytes as \xNN), so a
// binary file never prints raw bytes.
//
// Memory is bounded: a line is at most Limits::max_line_bytes, a file at most
// Limits::max_file_bytes and Limits::max_rows rows; a file that is not text (a NUL or another
// control byte) stops at its first such line. Reading /dev/zero ends at once with one line.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace feeddrive::csv {

class CsvError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct Limits {
  std::size_t max_line_bytes{1 << 20};                   ///< 1 MiB
  std::uint64_t max_file_bytes{std::uint64_t{4} << 30};  ///< 4 GiB
  std::size_t max_rows{50'000'000};                      ///< e.g. 1.4 hours at 10 kHz
  std::size_t min_rows{1};                               ///< fewer data rows is an error
};

/// A column asked for: the first of `names` that the header has is used.
struct Column {
  std::vector<std::string> names;
  bool required{true};
};

struct Table {
  std::string source;                       ///< the file name, for messages
  std::vector<std::string> used;            ///< the name used for each Column ("" if absent)
  std::vector<int> alternative;             ///< which of the Column's names was used (-1 if absent)
  std::vector<std::vector<double>> values;  ///< values[c][row]; empty for an absent column
  std::vector<long> lines;                  ///< the file line of each row
  std::size_t rows() const { return lines.size(); }
  bool has(std::size_t c) const { return !used[c].empty(); }
};

struct Options {
  std::vector<Column> columns;
  /// The column separator (',' by default; ';' or '\t' for loggers that write them).
  char separator{','};
  /// Numbers written with a decimal comma ("0,25"): the comma is read as the point (the
  /// separator must then be another character).
  bool decimal_comma{false};
  /// A column name that the header lacks and that is a positive integer N names the N-th column
  /// (1-based), e.g. a logger's unnamed or awkwardly named columns.
  bool columns_by_index{false};
  /// Named in the hint when a header seems split by another separator (e.g. "--separator").
  std::string separator_option;
  /// Named in the hint when a value that is not a number looks like one with a decimal comma
  /// ("0,25" without decimal_comma; e.g. "--decimal-comma").
  std::string decimal_comma_option;
  /// Index into columns of a column that must increase strictly (time), or -1.
  int increasing{-1};
  Limits limits;
};

/// Reads file `path`. Throws CsvError.
Table read_file(const std::string& path, const Options& opt);
/// Parses `text`; `origin` names it in messages.
Table parse(std::string_view text, const std::string& origin, const Options& opt);

/// `value` as a message shows it: at most `max` bytes, printable ASCII kept, every other byte as
/// \xNN, "..." when cut.
std::string shown(std::string_view value, std::size_t max = 40);

}  // namespace feeddrive::csv
