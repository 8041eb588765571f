#pragma once
// Writing CSV files fast and exactly: numbers in their shortest round-trip form
// (std::to_chars, C++17 [charconv]: the shortest text that from_chars/strtod reads back as the
// same double), rows streamed through a 1 MiB buffer straight to the file descriptor. This is
// the one number format of every feeddrive data file (timeseries.csv, the plot data, the fit's
// replay.csv), so two writers of the same values write the same bytes.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace feeddrive::output {

/// Longest text format_number writes ("-2.2250738585072014e-308").
inline constexpr std::size_t kMaxNumberChars = 24;

/// Writes the shortest round-trip text of v at `first` (room for kMaxNumberChars), returns the
/// end. NaN is "nan" (or "-nan"), infinities "inf" and "-inf".
char* format_number(char* first, double v);
/// The same as a string.
std::string number_text(double v);

/// A CSV file written row by row. Not copyable; close() reports write errors (the destructor
/// closes silently).
class CsvWriter {
 public:
  /// Creates (truncates) `path` and writes the header line `columns` joined by commas.
  /// Throws std::runtime_error naming the file.
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  /// One row of n numbers.
  void row(const double* values, std::size_t n);
  void row(const std::vector<double>& values) { row(values.data(), values.size()); }
  /// Flushes and closes; throws std::runtime_error on any write error.
  void close();
  /// Hands the buffered rows to the file (the kernel's page cache: a process killed after this
  /// loses none of them); throws std::runtime_error on a write error.
  void flush();
  std::uint64_t rows() const { return rows_; }
  /// Bytes of text so far, header included (written to the file or still in the buffer).
  std::uint64_t bytes() const { return bytes_ + used_; }

 private:
  std::filesystem::path path_;
  int fd_{-1};
  std::vector<char> buf_;
  std::size_t used_{0};
  std::uint64_t rows_{0}, bytes_{0};
};

}  // namespace feeddrive::output
