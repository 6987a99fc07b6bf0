#pragma once
/// \file
/// \brief Numeric CSV tables (docs/formats.md sections 2 and 3): a strict, fast
/// reader with one-line errors naming file, line and column, and a full-precision writer.
///
/// Accepted: a UTF-8 byte-order mark; CRLF or LF line endings; any number of
/// comment lines starting with '#' (before the header, and skipped anywhere
/// else); blank lines before the header and at the end; spaces around cells;
/// double quotes around header names; a leading '+' on numbers. Not accepted:
/// anything else (quoted cells with commas inside, ';' separators, ',' decimals,
/// NaN or Inf, empty cells, blank lines between data rows).
///
/// Nothing here knows a robot: the data sets of a robot (csv.hpp) build on it.

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "softrne/io/errors.hpp"

namespace softrne::io {

/// \brief Longest accepted CSV line in bytes (a longer one is an InputError, LineTooLong).
inline constexpr std::size_t kMaxLineLength = std::size_t{1} << 20;

/// \brief A numeric CSV table: every cell of every column is a finite number.
struct Table {
  std::vector<std::string> header;  ///< the column names, in file order
  Eigen::MatrixXd values;           ///< rows x cols, columns in header order
  std::string source;               ///< the file, for messages
};

/// \brief Index of column `name` in `table.header`, or -1.
/// \param[in] table A table.
/// \param[in] name A column name.
/// \return The column's index, or -1 if the table has none of that name.
inline Eigen::Index find_column(const Table& table, const std::string& name) {
  const auto it = std::find(table.header.begin(), table.header.end(), name);
  return it == table.header.end() ? -1 : static_cast<Eigen::Index>(it - table.header.begin());
}

namespace detail {

inline std::string_view trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return s.substr(b, e - b);
}

/// \brief Split `line` at commas into (untrimmed) cells.
inline void split_cells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  const char* p = line.data();
  const char* end = p + line.size();
  for (;;) {
    const void* c = std::memchr(p, ',', static_cast<std::size_t>(end - p));
    if (c == nullptr) {
      cells.emplace_back(p, static_cast<std::size_t>(end - p));
      return;
    }
    const char* q = static_cast<const char*>(c);
    cells.emplace_back(p, static_cast<std::size_t>(q - p));
    p = q + 1;
  }
}

/// \brief Clinger's exact fast path for the plain decimals recordings are made of
/// ([-]digits[.digits], e.g. "53474.6", "-0.153945"): with the digits as an integer m of at
/// most 2^53 and k <= 22 digits after the point, m and 10^k are exact doubles, so the one
/// division m / 10^k is the correctly rounded value, bit for bit what std::from_chars
/// gives. Anything else (more digits, an exponent, "inf", stray characters) returns false
/// and is left to std::from_chars.
///
/// Why: libstdc++'s from_chars cost 195 instructions per number, 5 % of a whole softrne-sim
/// run on the tiled bundled test run (callgrind, 2026-12-07); this path costs a fraction
/// (docs/performance.md). tests/io/test_csv.cpp holds it to from_chars on random decimals.
/// \param[in] b The first character of the number (after any '+').
/// \param[in] e One past its last character.
/// \param[out] out The value, if true is returned.
/// \return true if [b, e) is such a decimal and out holds its value.
inline bool parse_plain_decimal(const char* b, const char* e, double& out) {
  // Exact only with IEEE doubles and no extended-precision intermediates (x87): elsewhere
  // every number goes to from_chars.
  if constexpr (!(std::numeric_limits<double>::is_iec559 && FLT_EVAL_METHOD == 0)) return false;
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const bool negative = b < e && *b == '-';
  if (negative) ++b;
  // The digits before and after the point, as one integer (it wraps beyond 19 digits, which
  // are refused below anyway).
  std::uint64_t m = 0;
  const char* p = b;
  auto digit = [&]() { return p < e && static_cast<unsigned>(*p - '0') <= 9u; };
  for (; digit(); ++p) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
  const std::ptrdiff_t before_point = p - b;
  std::ptrdiff_t after_point = 0;
  if (p < e && *p == '.') {
    const char* first = ++p;
    for (; digit(); ++p) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    after_point = p - first;
  }
  const std::ptrdiff_t digits = before_point + after_point;
  if (p != e || digits == 0 || digits > 19 || m > (std::uint64_t(1) << 53) || after_point > 22)
    return false;
  const double v = static_cast<double>(m) / kPow10[after_point];
  out = negative ? -v : v;
  return true;
}

/// \brief Result of parsing one cell.
enum class NumberStatus { Ok, Empty, NotANumber, NonFinite };

/// \brief Parse a whole cell as a double (spaces around it and a leading '+' allowed).
inline NumberStatus parse_number(std::string_view cell, double& out) {
  cell = trim(cell);
  if (cell.empty()) return NumberStatus::Empty;
  const char* b = cell.data();
  const char* e = b + cell.size();
  if (*b == '+' && e - b > 1 && (b[1] == '.' || (b[1] >= '0' && b[1] <= '9'))) ++b;
  if (parse_plain_decimal(b, e, out)) return NumberStatus::Ok;
  const auto r = std::from_chars(b, e, out, std::chars_format::general);
  if (r.ec == std::errc::result_out_of_range && r.ptr == e) {
    // Overflow is an error; underflow reads as the nearest subnormal or zero.
    const std::string copy(b, e);
    out = std::strtod(copy.c_str(), nullptr);
    return std::isfinite(out) ? NumberStatus::Ok : NumberStatus::NonFinite;
  }
  if (r.ec != std::errc() || r.ptr != e) return NumberStatus::NotANumber;
  return std::isfinite(out) ? NumberStatus::Ok : NumberStatus::NonFinite;
}

inline std::string line_where(std::size_t line) {
  return "line " + std::to_string(line);
}

inline std::string cell_where(std::size_t line, const std::string& column) {
  return "line " + std::to_string(line) + ", column '" + column + "'";
}

/// \brief Scans a CSV text: header first, then the data rows.
class CsvScanner {
 public:
  CsvScanner(std::string_view text, const std::string& source) : text_(text), source_(source) {
    if (text_.size() >= 3 && text_.compare(0, 3, "\xEF\xBB\xBF") == 0) text_.remove_prefix(3);
    std::string_view line;
    bool any_comment = false;
    while (next_line(line)) {
      if (!line.empty() && line[0] == '#') {
        any_comment = true;
        continue;
      }
      if (trim(line).empty()) continue;
      header_line_ = line_no_;
      std::vector<std::string_view> cells;
      split_cells(line, cells);
      for (auto c : cells) {
        c = trim(c);
        if (c.size() >= 2 && c.front() == '"' && c.back() == '"')
          c = trim(c.substr(1, c.size() - 2));
        header_.emplace_back(c);
      }
      check_header();
      return;
    }
    throw InputError(
        Category::Empty, source_, "",
        any_comment ? "no header line (only comments)" : "empty file (no header line)");
  }

  const std::vector<std::string>& header() const { return header_; }
  std::size_t header_line() const { return header_line_; }
  std::string header_where() const { return line_where(header_line_) + " (header)"; }

  /// \brief Parse every data row; the cells of columns `wanted` go to `out`
  /// (row-major), then `check(row_pointer, line)` runs. Returns the number of rows.
  template <class Check>
  std::size_t read_rows(const std::vector<std::size_t>& wanted, std::vector<double>& out,
                        Check&& check) {
    // Every row has a newline but perhaps the last: an upper bound for the reservation.
    const std::size_t max_rows =
        static_cast<std::size_t>(
            std::count(text_.begin() + static_cast<std::ptrdiff_t>(pos_), text_.end(), '\n')) +
        1;
    out.reserve(out.size() + max_rows * wanted.size());
    std::vector<std::string_view> cells;
    cells.reserve(header_.size() + 1);
    std::size_t rows = 0;
    std::size_t blank_line = 0;  // first blank line after the last row, if any
    std::string_view line;
    while (next_line(line)) {
      if (!line.empty() && line[0] == '#') continue;
      if (trim(line).empty()) {
        if (blank_line == 0) blank_line = line_no_;
        continue;
      }
      if (blank_line != 0)
        throw InputError(
            Category::BadRowLength, source_, line_where(blank_line),
            "blank line inside the data (data continues on line " + std::to_string(line_no_) + ")");
      split_cells(line, cells);
      if (cells.size() != header_.size())
        throw InputError(Category::BadRowLength, source_, line_where(line_no_),
                         "expected " + std::to_string(header_.size()) +
                             " cells as in the header, got " + std::to_string(cells.size()));
      const std::size_t base = out.size();
      for (std::size_t w : wanted) {
        double v = 0.0;
        switch (parse_number(cells[w], v)) {
          case NumberStatus::Ok:
            break;
          case NumberStatus::Empty:
            throw InputError(Category::BadNumber, source_, cell_where(line_no_, header_[w]),
                             "empty cell");
          case NumberStatus::NotANumber:
            throw InputError(Category::BadNumber, source_, cell_where(line_no_, header_[w]),
                             "not a number: " + quoted(std::string(trim(cells[w]))));
          case NumberStatus::NonFinite:
            throw InputError(Category::NonFinite, source_, cell_where(line_no_, header_[w]),
                             "not a finite number: " + quoted(std::string(trim(cells[w]))));
        }
        out.push_back(v);
      }
      check(out.data() + base, line_no_);
      ++rows;
    }
    return rows;
  }

 private:
  /// Next physical line without its "\n" or "\r\n"; false at the end.
  bool next_line(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    ++line_no_;
    const std::size_t rest = text_.size() - pos_;
    const void* nl = std::memchr(text_.data() + pos_, '\n', rest);
    const std::size_t len =
        nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - (text_.data() + pos_)) : rest;
    if (len > kMaxLineLength)
      throw InputError(
          Category::LineTooLong, source_, line_where(line_no_),
          "line longer than " + std::to_string(kMaxLineLength) + " bytes (is this a CSV file?)");
    line = text_.substr(pos_, len);
    pos_ += len + (nl ? 1 : 0);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return true;
  }

  void check_header() const {
    std::unordered_map<std::string, std::size_t> seen;
    for (std::size_t i = 0; i < header_.size(); ++i) {
      if (header_[i].empty()) continue;  // unnamed column (e.g. an exported index): ignored
      const auto [it, inserted] = seen.emplace(header_[i], i);
      if (!inserted)
        throw InputError(Category::DuplicateColumn, source_, header_where(),
                         "duplicate column '" + one_line(header_[i]) + "' (columns " +
                             std::to_string(it->second + 1) + " and " + std::to_string(i + 1) +
                             ")");
    }
  }

  std::string_view text_;
  const std::string& source_;
  std::size_t pos_ = 0;
  std::size_t line_no_ = 0;
  std::size_t header_line_ = 0;
  std::vector<std::string> header_;
};

inline void check_column_name(const std::string& name) {
  if (name.find_first_of(",\n\r\"") != std::string::npos)
    throw std::invalid_argument(
        "softrne::io: CSV column name must not contain ',', '\"' or a line break: " + name);
}

}  // namespace detail

/// \brief Parse a CSV text into a table (all columns must be numeric).
/// \param[in] text The file's content.
/// \param[in] source The file's name, for messages.
/// \return The table.
/// \throws InputError (Empty, BadRowLength, BadNumber, NonFinite, DuplicateColumn,
///   LineTooLong, ...) naming source, line and column.
inline Table parse_csv(const std::string& text, const std::string& source) {
  detail::CsvScanner scan(text, source);
  std::vector<std::size_t> wanted(scan.header().size());
  for (std::size_t i = 0; i < wanted.size(); ++i) wanted[i] = i;
  std::vector<double> data;
  const std::size_t rows = scan.read_rows(wanted, data, [](const double*, std::size_t) {});
  Table table;
  table.header = scan.header();
  table.source = source;
  table.values =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          data.data(), static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(wanted.size()));
  return table;
}

/// \brief Read a CSV file into a table (all columns must be numeric).
/// \param[in] path The file.
/// \return The table.
/// \throws InputError (FileNotFound, ReadFailed, or as parse_csv()).
inline Table read_csv(const std::string& path) {
  return parse_csv(detail::read_text_file(path), path);
}

/// \brief The CSV text of a table, preceded by `# ` comment lines; numbers in
/// shortest round-trip form (reading back gives bit-identical doubles).
/// \param[in] header The column names (one per column of values).
/// \param[in] values The table, rows x columns.
/// \param[in] comments Lines written first, each as `# line`.
/// \return The CSV text.
/// \throws std::invalid_argument if header and values disagree on the number of columns.
inline std::string format_csv(const std::vector<std::string>& header, const Eigen::MatrixXd& values,
                              const std::vector<std::string>& comments = {}) {
  if (static_cast<Eigen::Index>(header.size()) != values.cols())
    throw std::invalid_argument("softrne::io: CSV header has " + std::to_string(header.size()) +
                                " names but the table " + std::to_string(values.cols()) +
                                " columns");
  std::string out;
  for (const auto& c : comments) out += "# " + detail::one_line(c) + "\n";
  for (std::size_t i = 0; i < header.size(); ++i) {
    detail::check_column_name(header[i]);
    out += (i ? "," : "") + header[i];
  }
  out += '\n';
  out.reserve(out.size() + static_cast<std::size_t>(values.size()) * 12);
  char buf[64];
  for (Eigen::Index r = 0; r < values.rows(); ++r) {
    for (Eigen::Index c = 0; c < values.cols(); ++c) {
      if (c) out += ',';
      const auto res = std::to_chars(buf, buf + sizeof buf, values(r, c));
      out.append(buf, res.ptr);
    }
    out += '\n';
  }
  return out;
}

/// \brief Write a table as CSV (see format_csv); InputError (WriteFailed) on failure.
/// \param[in] path The output file (written to a temporary file, then renamed).
/// \param[in] table The table.
/// \param[in] comments Lines written first, each as `# line`.
/// \throws InputError (WriteFailed) if the file cannot be written.
inline void write_csv(const std::string& path, const Table& table,
                      const std::vector<std::string>& comments = {}) {
  detail::write_text_file(path, format_csv(table.header, table.values, comments));
}

}  // namespace softrne::io
