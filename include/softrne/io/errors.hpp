#pragma once
/// \file
/// \brief The one exception type of softrne::io: a bad input file, with a
/// machine-readable category and a one-line human-readable message
/// `"<file>: <where>: <what>"`.

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

namespace softrne::io {

/// \brief What kind of problem an InputError reports (stable: tests and tools
/// may switch on it).
enum class Category {
  FileNotFound,      ///< the file does not exist
  ReadFailed,        ///< the file exists but cannot be read (permissions, a directory, I/O error)
  WriteFailed,       ///< an output file cannot be written
  Empty,             ///< empty file, or an empty list where one entry at least is needed
  Syntax,            ///< JSON syntax error (the message gives line and column)
  UnknownFormat,     ///< the `format` version string is not the one this reader knows
  MissingField,      ///< a required JSON field is absent
  UnknownField,      ///< a JSON field this format does not define (usually a typo)
  DuplicateField,    ///< the same key twice in one JSON object
  WrongType,         ///< e.g. a string where a number is needed
  UnknownType,       ///< a segment `type` that does not exist
  NonFinite,         ///< NaN, infinity, or a number that overflows a double
  OutOfRange,        ///< a number outside its allowed interval (mass <= 0, ...)
  InvalidValue,      ///< a value that breaks a structural rule (axis not unit, inertia not positive
                     ///< definite, ...)
  BadShape,          ///< an array or matrix of the wrong length or shape
  DuplicateName,     ///< two segments with the same name
  UnknownName,       ///< a reference to a segment that does not exist
  MissingColumn,     ///< a CSV column the robot needs is absent
  DuplicateColumn,   ///< the same CSV column name twice
  UnexpectedColumn,  ///< a pressure/angle column that the robot does not have (robot and data
                     ///< disagree)
  BadRowLength,      ///< a CSV row with the wrong number of cells (or a blank line inside the data)
  BadNumber,         ///< a CSV cell that is not a number
  NonIncreasingTime,  ///< CSV time column not strictly increasing
  TooFewRows,         ///< fewer than two data rows
  LineTooLong,        ///< a CSV line longer than the limit (1 MiB)
};

/// \brief Name of a category, e.g. "MissingField".
/// \param[in] c A category.
/// \return Its name (the enumerator's).
inline const char* to_string(Category c) noexcept {
  switch (c) {
    case Category::FileNotFound:
      return "FileNotFound";
    case Category::ReadFailed:
      return "ReadFailed";
    case Category::WriteFailed:
      return "WriteFailed";
    case Category::Empty:
      return "Empty";
    case Category::Syntax:
      return "Syntax";
    case Category::UnknownFormat:
      return "UnknownFormat";
    case Category::MissingField:
      return "MissingField";
    case Category::UnknownField:
      return "UnknownField";
    case Category::DuplicateField:
      return "DuplicateField";
    case Category::WrongType:
      return "WrongType";
    case Category::UnknownType:
      return "UnknownType";
    case Category::NonFinite:
      return "NonFinite";
    case Category::OutOfRange:
      return "OutOfRange";
    case Category::InvalidValue:
      return "InvalidValue";
    case Category::BadShape:
      return "BadShape";
    case Category::DuplicateName:
      return "DuplicateName";
    case Category::UnknownName:
      return "UnknownName";
    case Category::MissingColumn:
      return "MissingColumn";
    case Category::DuplicateColumn:
      return "DuplicateColumn";
    case Category::UnexpectedColumn:
      return "UnexpectedColumn";
    case Category::BadRowLength:
      return "BadRowLength";
    case Category::BadNumber:
      return "BadNumber";
    case Category::NonIncreasingTime:
      return "NonIncreasingTime";
    case Category::TooFewRows:
      return "TooFewRows";
    case Category::LineTooLong:
      return "LineTooLong";
  }
  return "Unknown";
}

namespace detail {

/// \brief `s` with control characters escaped, so that it fits on one line.
inline std::string one_line(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += ch;
    }
  }
  return out;
}

/// \brief A user-supplied snippet for a message: one line, at most `max_len`
/// characters, in single quotes.
inline std::string quoted(const std::string& s, std::size_t max_len = 40) {
  std::string t = one_line(s);
  if (t.size() > max_len) t = t.substr(0, max_len) + "...";
  return "'" + t + "'";
}

/// \brief Shortest text that reads back as exactly `v` ("0.1", "-1", "1e-07", "nan").
inline std::string format_double(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// \brief "<where>: field '<field>'".
inline std::string field_where(const std::string& where, const std::string& field) {
  return where.empty() ? "field '" + field + "'" : where + ": field '" + field + "'";
}

}  // namespace detail

/// \brief A file that softrne cannot use, and why.
///
/// `what()` is one line: `"<source>: <where>: <detail>"` (or `"<source>: <detail>"`
/// when there is no finer location), e.g.
/// `robot.json: segments[2] 'joint2': field 'mass': must be > 0 (got -1)` or
/// `train.csv: line 17, column 'u2': not a number: 'abc'`.
class InputError : public std::runtime_error {
 public:
  /// \brief The error; what() is `source: where: detail` on one line.
  /// \param category what kind of problem
  /// \param source the file (as the user named it)
  /// \param where location inside the file ("" if none): field path or line/column
  /// \param detail what is wrong
  InputError(Category category, std::string source, std::string where, std::string detail)
      : std::runtime_error(compose(source, where, detail)),
        category_(category),
        source_(std::move(source)),
        where_(std::move(where)),
        detail_(std::move(detail)) {}

  /// \return What kind of problem.
  Category category() const noexcept { return category_; }
  /// \return The file, as given by the user.
  const std::string& source() const noexcept { return source_; }
  /// \return Location inside the file (may be empty).
  const std::string& where() const noexcept { return where_; }
  /// \return The description without file and location.
  const std::string& detail() const noexcept { return detail_; }

 private:
  static std::string compose(const std::string& source, const std::string& where,
                             const std::string& detail) {
    using ::softrne::io::detail::one_line;
    std::string m = one_line(source.empty() ? std::string("<input>") : source);
    if (!where.empty()) m += ": " + one_line(where);
    m += ": " + one_line(detail);
    return m;
  }

  Category category_;
  std::string source_;
  std::string where_;
  std::string detail_;
};

namespace detail {

/// \brief The whole content of a file; InputError (FileNotFound / ReadFailed) if
/// it cannot be read.
inline std::string read_text_file(const std::string& path) {
  errno = 0;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    const int err = errno;
    throw InputError(err == ENOENT ? Category::FileNotFound : Category::ReadFailed, path, "",
                     std::string("cannot open file: ") + std::strerror(err));
  }
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const std::size_t n = std::fread(buf, 1, sizeof buf, f);
    text.append(buf, n);
    if (n < sizeof buf) break;
  }
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed) {
    throw InputError(Category::ReadFailed, path, "",
                     std::string("cannot read file: ") + std::strerror(err != 0 ? err : EIO));
  }
  return text;
}

/// \brief Write `text` to `path` directly (truncating it first); InputError (WriteFailed) on
/// failure. For devices and pipes; write_text_file for files.
inline void write_text_file_in_place(const std::string& path, const std::string& text) {
  errno = 0;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    throw InputError(Category::WriteFailed, path, "",
                     std::string("cannot open file for writing: ") + std::strerror(errno));
  }
  const std::size_t n = std::fwrite(text.data(), 1, text.size(), f);
  int err = errno;
  const bool failed = n != text.size() || std::fflush(f) != 0;
  if (failed && err == 0) err = errno;
  if (std::fclose(f) != 0 && !failed) {
    throw InputError(Category::WriteFailed, path, "",
                     std::string("cannot write file: ") + std::strerror(errno));
  }
  if (failed) {
    throw InputError(Category::WriteFailed, path, "",
                     std::string("cannot write file: ") + std::strerror(err != 0 ? err : EIO));
  }
}

/// \brief Write `text` to `path` (replacing it); InputError (WriteFailed) on failure.
///
/// A regular file (or a new one) is replaced atomically: the text goes to a temporary file
/// next to it, which is renamed over `path` only once it is complete, so an interrupted or
/// failed write never leaves a truncated file, and the old content survives any failure.
/// A path through a symbolic link replaces the link's target. Anything else (a device such as
/// /dev/null or /dev/stdout, a pipe) is written in place.
inline void write_text_file(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path target(path);
  const fs::file_status st = fs::status(target, ec);  // follows links
  const bool exists = !ec && fs::exists(st);
  if (exists && !fs::is_regular_file(st)) {
    write_text_file_in_place(path, text);
    return;
  }
  if (exists && fs::is_symlink(fs::symlink_status(target, ec))) target = fs::canonical(target, ec);
  if (ec) target = fs::path(path);
  // Same directory, so that the rename is atomic; a name no other writer uses.
  std::random_device rd;
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, ".part-%08x", static_cast<unsigned>(rd()));
  const std::string tmp = target.string() + suffix;
  try {
    write_text_file_in_place(tmp, text);
  } catch (const InputError& e) {
    std::remove(tmp.c_str());
    throw InputError(Category::WriteFailed, path, "", e.detail());  // the user's path, not tmp
  }
  if (std::rename(tmp.c_str(), target.string().c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw InputError(Category::WriteFailed, path, "",
                     std::string("cannot replace file: ") + std::strerror(err));
  }
}

}  // namespace detail
}  // namespace softrne::io
