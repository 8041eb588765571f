#include "feeddrive/csv/reader.hpp"
#include "feeddrive/common/text_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>

namespace feeddrive::csv {
namespace {

constexpr std::string_view kBom = "\xEF\xBB\xBF";

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

struct Field {
  std::string_view text;  // trimmed
  std::size_t column;     // 1-based byte column of the field's first byte
};

void split(std::string_view line, char sep, std::vector<Field>& out) {
  out.clear();
  std::size_t start = 0;
  for (;;) {
    const auto comma = line.find(sep, start);
    const std::string_view raw =
        line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    const auto lead = raw.find_first_not_of(" \t");
    out.push_back({trim(raw), start + 1 + (lead == std::string_view::npos ? 0 : lead)});
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

std::string unquote(std::string_view s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return std::string(s);
}

class Parser {
 public:
  Parser(std::string origin, const Options& opt) : origin_(std::move(origin)), opt_(opt) {
    table_.source = origin_;
    table_.used.assign(opt.columns.size(), "");
    table_.alternative.assign(opt.columns.size(), -1);
    table_.values.assign(opt.columns.size(), {});
    index_.assign(opt.columns.size(), -1);
  }

  // One line without its '\n' (the caller enforces the line-length limit).
  void line(std::string_view l) {
    ++line_no_;
    if (line_no_ == 1 && l.substr(0, kBom.size()) == kBom) {
      l.remove_prefix(kBom.size());
      bom_ = kBom.size();
    } else {
      bom_ = 0;
    }
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    for (std::size_t i = 0; i < l.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(l[i]);
      if ((c < 0x20 && c != '\t') || c == 0x7f)
        fail_line(i + 1 + bom_,
                  "not a text file: byte " + hex(c) + " in \"" + shown(l.substr(i >= 8 ? i - 8 : 0), 24) + "\"");
    }
    const std::string_view t = trim(l);
    if (t.empty() || t.front() == '#') return;
    split(l, opt_.separator, fields_);
    if (!have_header_) {
      header(l);
      return;
    }
    row();
  }

  Table finish() {
    if (!have_header_) {
      std::string want;
      for (const Column& c : opt_.columns)
        if (c.required) want += (want.empty() ? "" : ", ") + c.names.front();
      throw CsvError(origin_ + ": no header line (expected the columns " + want + ")");
    }
    if (table_.rows() < opt_.limits.min_rows)
      throw CsvError(origin_ + ":" + std::to_string(line_no_) + ": need at least " +
                     std::to_string(opt_.limits.min_rows) + " data rows, found " + std::to_string(table_.rows()) +
                     " (end of file)");
    return std::move(table_);
  }

  [[noreturn]] void fail_line(std::size_t col, const std::string& why) const {
    throw CsvError(origin_ + ":" + std::to_string(line_no_) + (col ? ":" + std::to_string(col) : "") + ": " + why);
  }
  long line_no() const { return line_no_; }

 private:
  static std::string hex(unsigned char c) {
    static const char* d = "0123456789ABCDEF";
    return std::string("0x") + d[c >> 4] + d[c & 15];
  }

  void header(std::string_view l) {
    have_header_ = true;
    header_text_ = shown(trim(l), 60);
    std::map<std::string, std::size_t> seen;
    // a separator after the last name (a logger's "t;x;F;"): no column, and rows may end with one
    // too (issue 20's review); an empty name elsewhere stays an error
    trailing_ = fields_.size() > 1 && unquote(fields_.back().text).empty();
    if (trailing_) fields_.pop_back();
    for (std::size_t i = 0; i < fields_.size(); ++i) {
      const std::string name = unquote(fields_[i].text);
      if (name.empty())
        fail_line(fields_[i].column + bom_, "empty column name (column " + std::to_string(i + 1) + " of the header)");
      if (!seen.emplace(name, i).second)
        fail_line(fields_[i].column + bom_, "duplicate column '" + shown(name) + "' in the header");
      header_.push_back(name);
    }
    bool one = false;
    for (const char other : {',', ';', '\t'})
      one = one || (other != opt_.separator && fields_.size() == 1 && l.find(other) != std::string_view::npos);
    const std::string sep_name = opt_.separator == ','    ? "commas"
                                 : opt_.separator == '\t' ? "tabs"
                                                          : "'" + std::string(1, opt_.separator) + "'";
    const std::string hint =
        one ? "; columns must be separated by " + sep_name +
                  (opt_.separator_option.empty() ? "" : " (or give the separator with " + opt_.separator_option + ")")
            : "";
    for (std::size_t c = 0; c < opt_.columns.size(); ++c) {
      for (std::size_t a = 0; a < opt_.columns[c].names.size(); ++a) {
        const std::string& n = opt_.columns[c].names[a];
        if (const auto it = seen.find(n); it != seen.end()) {
          index_[c] = static_cast<long>(it->second);
          table_.used[c] = n;
          table_.alternative[c] = static_cast<int>(a);
          break;
        }
      }
      if (index_[c] < 0 && opt_.columns_by_index) {
        for (std::size_t a = 0; a < opt_.columns[c].names.size(); ++a) {
          const std::string& n = opt_.columns[c].names[a];
          const bool digits = !n.empty() && n.size() < 6 && n.find_first_not_of("0123456789") == std::string::npos;
          const long k = digits ? std::stol(n) : 0;
          if (k >= 1 && k <= static_cast<long>(header_.size())) {
            index_[c] = k - 1;
            table_.used[c] = header_[static_cast<std::size_t>(k - 1)];
            table_.alternative[c] = static_cast<int>(a);
            break;
          }
        }
      }
      if (index_[c] < 0 && opt_.columns[c].required) {
        std::string alts;
        bool index_given = false;  // a column asked for by an index the header does not reach
        for (const std::string& n : opt_.columns[c].names) {
          alts += (alts.empty() ? "'" : " or '") + n + "'";
          index_given = index_given ||
                        (opt_.columns_by_index && !n.empty() && n.find_first_not_of("0123456789") == std::string::npos);
        }
        const std::string range =
            index_given ? "; a column index is 1 to " + std::to_string(header_.size()) + " here" : "";
        fail_line(0, "missing column " + alts + " in the header '" + header_text_ + "'" + hint + range);
      }
    }
  }

  void row() {
    if (trailing_ && fields_.size() == header_.size() + 1 && trim(fields_.back().text).empty()) fields_.pop_back();
    if (fields_.size() != header_.size())
      fail_line(0, std::to_string(fields_.size()) + " fields, the header has " + std::to_string(header_.size()) +
                       " (truncated or extra field?)");
    if (table_.rows() >= opt_.limits.max_rows)
      fail_line(0, "more than " + std::to_string(opt_.limits.max_rows) + " data rows (the reader's limit)");
    for (std::size_t c = 0; c < index_.size(); ++c) {
      if (index_[c] < 0) continue;
      const Field& f = fields_[static_cast<std::size_t>(index_[c])];
      const double v = number(f, table_.used[c]);
      auto& col = table_.values[c];
      if (static_cast<int>(c) == opt_.increasing && !col.empty() && !(v > col.back()))
        fail_line(f.column + bom_, "column '" + table_.used[c] + "': " + shown(f.text) +
                                       " is not greater than the previous " + table_.used[c] + " = " + previous_text_ +
                                       " (line " + std::to_string(table_.lines.back()) + ")");
      if (static_cast<int>(c) == opt_.increasing) previous_text_ = shown(f.text);
      col.push_back(v);
    }
    table_.lines.push_back(line_no_);
  }

  // "; a decimal comma? ..." for a value that would be a number with its comma read as the point
  // (only without decimal_comma: a logger's "0,25" in a ';'-separated file); "" otherwise.
  std::string decimal_comma_hint(std::string_view text) const {
    if (opt_.decimal_comma || text.find(',') == std::string_view::npos) return "";
    std::string t(text);
    std::replace(t.begin(), t.end(), ',', '.');
    double v = 0.0;
    const char* first = t.data() + (t.front() == '+' ? 1 : 0);
    const auto res = std::from_chars(first, t.data() + t.size(), v);
    if (res.ec != std::errc() || res.ptr != t.data() + t.size()) return "";
    return "; a decimal comma?" + (opt_.decimal_comma_option.empty()
                                       ? std::string(" (it is read only when asked for)")
                                       : " (give it with " + opt_.decimal_comma_option + ")");
  }

  double number(const Field& f, const std::string& name) const {
    const std::string where = "column '" + name + "': ";
    const std::size_t col = f.column + bom_;
    if (f.text.empty()) fail_line(col, where + "missing value");
    std::string comma_text;
    std::string_view text = f.text;
    if (opt_.decimal_comma) {  // "0,25" is 0.25; a point in such a file is not a number
      comma_text.assign(text);
      if (comma_text.find('.') != std::string::npos)
        fail_line(col, where + "not a number with a decimal comma: '" + shown(f.text) + "'");
      std::replace(comma_text.begin(), comma_text.end(), ',', '.');
      text = comma_text;
    }
    const char* first = text.data();
    const char* last = first + text.size();
    if (*first == '+') ++first;
    double v = 0.0;
    const auto res = std::from_chars(first, last, v);
    if (first == last || res.ptr != last || (res.ec != std::errc() && res.ec != std::errc::result_out_of_range))
      fail_line(col, where + "not a number: '" + shown(f.text) + "'" + decimal_comma_hint(text));
    if (res.ec == std::errc::result_out_of_range)
      fail_line(col, where + "out of the range of a double: '" + shown(f.text) + "'");
    if (!std::isfinite(v)) fail_line(col, where + "not a finite number: '" + shown(f.text) + "'");
    return v;
  }

  std::string origin_;
  const Options& opt_;
  Table table_;
  std::vector<long> index_;
  std::vector<std::string> header_;
  bool trailing_{false};  // the header ends with a separator
  std::string header_text_, previous_text_;
  std::vector<Field> fields_;
  long line_no_{0};
  std::size_t bom_{0};  // bytes of a byte-order mark before the current line's text (line 1)
  bool have_header_{false};
};

// A control byte other than tab and CR: the file is not text.
bool binary(std::string_view s) {
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) return true;
  }
  return false;
}

}  // namespace

std::string shown(std::string_view value, std::size_t max) {
  static const char* d = "0123456789ABCDEF";
  std::string out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (i >= max) return out + "...";
    const unsigned char c = static_cast<unsigned char>(value[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += d[c >> 4];
      out += d[c & 15];
    }
  }
  return out;
}

Table parse(std::string_view text, const std::string& origin, const Options& opt) {
  Parser p(origin, opt);
  std::size_t start = 0;
  while (start < text.size()) {
    auto nl = text.find('\n', start);
    if (nl == std::string_view::npos) nl = text.size();
    if (nl - start > opt.limits.max_line_bytes)
      throw CsvError(origin + ":" + std::to_string(p.line_no() + 1) + ": line longer than " +
                     std::to_string(opt.limits.max_line_bytes) + " bytes (not a CSV file?)");
    p.line(text.substr(start, nl - start));
    start = nl + 1;
  }
  return p.finish();
}

Table read_file(const std::string& path, const Options& opt) {
  const std::string who = shown(path, 200);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);  // a FIFO must not block open()
  if (fd < 0) throw CsvError(who + ": cannot open the file: " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw CsvError(who + ": is a folder, not a data file");
    if (!S_ISREG(st.st_mode))
      throw CsvError(who + ": is " + text::non_regular_kind(st.st_mode) + ", not a regular file");
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    if (S_ISREG(st.st_mode) && static_cast<std::uint64_t>(st.st_size) > opt.limits.max_file_bytes)
      throw CsvError(who + ": " + std::to_string(st.st_size) + " bytes, larger than the reader's limit of " +
                     std::to_string(opt.limits.max_file_bytes) + " bytes");
  }
  Parser p(who, opt);
  std::vector<char> buf(std::size_t{1} << 16);
  std::string pending;  // the unfinished line, at most max_line_bytes
  std::uint64_t total = 0;
  for (;;) {
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      throw CsvError(who + ": read error: " + std::strerror(errno));
    }
    if (n == 0) break;
    total += static_cast<std::uint64_t>(n);
    if (total > opt.limits.max_file_bytes)
      throw CsvError(who + ": larger than the reader's limit of " + std::to_string(opt.limits.max_file_bytes) +
                     " bytes");
    std::string_view chunk(buf.data(), static_cast<std::size_t>(n));
    while (!chunk.empty()) {
      const auto nl = chunk.find('\n');
      const std::string_view piece = chunk.substr(0, nl);
      if (nl == std::string_view::npos || pending.size() + piece.size() > opt.limits.max_line_bytes) {
        // An unfinished line: if it is binary (e.g. /dev/zero), say so now from its first bytes
        // rather than after max_line_bytes; a text line that is too long is refused at the limit.
        if (binary(piece)) p.line(pending + std::string(piece));  // throws at the first control byte
        if (pending.size() + piece.size() > opt.limits.max_line_bytes)
          throw CsvError(who + ":" + std::to_string(p.line_no() + 1) + ": line longer than " +
                         std::to_string(opt.limits.max_line_bytes) + " bytes (not a CSV file?)");
      }
      pending.append(piece);
      if (nl == std::string_view::npos) break;
      p.line(pending);
      pending.clear();
      chunk.remove_prefix(nl + 1);
    }
  }
  if (!pending.empty()) p.line(pending);
  return p.finish();
}

}  // namespace feeddrive::csv
