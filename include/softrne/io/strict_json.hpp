#pragma once
/// \file
/// \brief Strict reading of JSON for the softrne::io readers: a parser that refuses
/// duplicate keys and documents nested deeper than a limit, and a reader of one object's
/// fields (required, typed, finite, no unknown keys) whose every error is an InputError
/// naming the file and the field, with a "did you mean" hint for a misspelt key.
///
/// Nothing here knows a file format: the schemas (robot_json.hpp) build on it.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "softrne/io/errors.hpp"

namespace softrne::io::detail {

/// \brief Levenshtein distance, for "did you mean" hints.
inline std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] =
          std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0u : 1u)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

/// \brief "; allowed: a, b, c" or "; did you mean 'mass'?".
inline std::string suggest(const std::string& key, const std::vector<std::string>& allowed) {
  std::size_t best = std::numeric_limits<std::size_t>::max();
  std::string best_name;
  for (const auto& a : allowed) {
    const std::size_t d = edit_distance(key, a);
    if (d < best) best = d, best_name = a;
  }
  if (!best_name.empty() && best <= std::max<std::size_t>(2, key.size() / 3))
    return "; did you mean '" + best_name + "'?";
  std::string s = "; allowed: ";
  for (std::size_t i = 0; i < allowed.size(); ++i) s += (i ? ", " : "") + allowed[i];
  return s;
}

/// \brief Deepest nesting of arrays and objects that parse_json_strict accepts.
/// Deeper documents are refused while parsing, before any recursion over them.
inline constexpr std::size_t kMaxJsonDepth = 64;

/// \brief True if `v` has at most `levels` levels of nested arrays/objects (the
/// recursion is bounded by `levels`, whatever the depth of `v`).
inline bool nesting_at_most(const nlohmann::json& v, int levels) {
  if (!v.is_structured()) return true;
  if (levels <= 0) return false;
  for (const auto& child : v)
    if (!nesting_at_most(child, levels - 1)) return false;
  return true;
}

/// \brief A short one-line rendering of a JSON value for messages.
inline std::string describe(const nlohmann::json& v) {
  if (v.is_null()) return "null";
  // dump() recurses once per level: a value nested thousands of levels deep (possible
  // for JSON parsed elsewhere than by parse_json_strict) would overflow the stack.
  if (!nesting_at_most(v, 16))
    return std::string(v.type_name()) + " nested more than 16 levels deep";
  std::string d;
  try {
    d = v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (...) {
    d = "?";
  }
  if (d.size() > 40) d = d.substr(0, 40) + "...";
  return std::string(v.type_name()) + " " + one_line(d);
}

/// \brief Reads fields of one JSON object, with errors that name source and place.
class ObjectReader {
 public:
  ObjectReader(const nlohmann::json& obj, const std::string& source, std::string where)
      : obj_(obj), source_(source), where_(std::move(where)) {}

  const std::string& where() const { return where_; }
  void set_where(std::string w) { where_ = std::move(w); }

  /// Throw UnknownField on the first key not in `allowed`.
  void only(const std::vector<std::string>& allowed) const {
    for (auto it = obj_.begin(); it != obj_.end(); ++it) {
      if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
        throw InputError(Category::UnknownField, source_, where_,
                         "unknown field " + quoted(it.key()) + suggest(it.key(), allowed));
    }
  }

  bool has(const char* key) const { return obj_.contains(key); }

  const nlohmann::json& at(const char* key) const {
    const auto it = obj_.find(key);
    if (it == obj_.end())
      throw InputError(Category::MissingField, source_, fw(key), "missing (required)");
    return *it;
  }

  double number(const char* key) const { return as_number(at(key), fw(key)); }

  std::string string(const char* key) const {
    const auto& v = at(key);
    if (!v.is_string())
      throw InputError(Category::WrongType, source_, fw(key),
                       "expected a string, got " + describe(v));
    return v.get<std::string>();
  }

  std::string optional_string(const char* key, std::string fallback) const {
    return has(key) ? string(key) : fallback;
  }

  int integer(const char* key) const {
    const auto& v = at(key);
    if (!v.is_number_integer())
      throw InputError(Category::WrongType, source_, fw(key),
                       "expected an integer, got " + describe(v));
    if (v.is_number_unsigned()) {
      const auto u = v.get<std::uint64_t>();
      if (u > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
        throw InputError(Category::OutOfRange, source_, fw(key),
                         "too large (got " + std::to_string(u) + ")");
      return static_cast<int>(u);
    }
    const auto i = v.get<std::int64_t>();
    if (i < std::numeric_limits<int>::min() || i > std::numeric_limits<int>::max())
      throw InputError(Category::OutOfRange, source_, fw(key),
                       "out of range (got " + std::to_string(i) + ")");
    return static_cast<int>(i);
  }

  /// A JSON array of exactly N numbers.
  template <int N>
  Eigen::Matrix<double, N, 1> fixed(const char* key) const {
    const auto& v = at(key);
    const std::string w = fw(key);
    check_array(v, w, N);
    Eigen::Matrix<double, N, 1> out;
    for (int i = 0; i < N; ++i)
      out[i] = as_number(v[static_cast<std::size_t>(i)], w + "[" + std::to_string(i) + "]", w, i);
    return out;
  }

  /// A JSON array (any length) of strings.
  std::vector<std::string> strings(const char* key) const {
    const auto& v = at(key);
    const std::string w = fw(key);
    if (!v.is_array())
      throw InputError(Category::WrongType, source_, w,
                       "expected an array of strings, got " + describe(v));
    std::vector<std::string> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string())
        throw InputError(
            Category::WrongType, source_, w,
            "element " + std::to_string(i) + ": expected a string, got " + describe(v[i]));
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }

  std::string fw(const std::string& key) const { return field_where(where_, key); }

  void check_array(const nlohmann::json& v, const std::string& w, int n) const {
    if (!v.is_array())
      throw InputError(
          Category::WrongType, source_, w,
          "expected an array of " + std::to_string(n) + " numbers, got " + describe(v));
    if (v.size() != static_cast<std::size_t>(n))
      throw InputError(
          Category::BadShape, source_, w,
          "expected " + std::to_string(n) + " numbers, got " + std::to_string(v.size()));
  }

  double as_number(const nlohmann::json& v, const std::string& w, const std::string& array_w = "",
                   int element = -1) const {
    if (!v.is_number()) {
      if (element >= 0)
        throw InputError(
            Category::WrongType, source_, array_w,
            "element " + std::to_string(element) + ": expected a number, got " + describe(v));
      throw InputError(Category::WrongType, source_, w, "expected a number, got " + describe(v));
    }
    const double d = v.get<double>();
    if (!std::isfinite(d))
      throw InputError(Category::NonFinite, source_, w, "must be a finite number");
    return d;
  }

 private:
  const nlohmann::json& obj_;
  const std::string& source_;
  std::string where_;
};

inline void require_object(const nlohmann::json& v, const std::string& source,
                           const std::string& where) {
  if (!v.is_object())
    throw InputError(Category::WrongType, source, where,
                     "expected a JSON object, got " + describe(v));
}

/// \brief Parse with duplicate-key detection (nlohmann keeps the last silently).
/// `depth_note` ends the message of a document nested deeper than kMaxJsonDepth; a format
/// says there how deep its documents go (e.g. " (a robot description needs 5)").
inline nlohmann::json parse_json_strict(const std::string& text, const std::string& source,
                                        const std::string& depth_note = "") {
  struct Frame {
    explicit Frame(bool array) : is_array(array) {}
    bool is_array;
    std::size_t index = 0;
    std::string last_key;
    std::vector<std::string> keys;
  };
  std::vector<Frame> stack;
  // Location of the innermost object or array (with_last: of the value being read in it).
  auto path = [&stack](bool with_last = false) {
    std::string p;
    for (std::size_t i = 0; i + (with_last ? 0 : 1) < stack.size(); ++i) {
      const Frame& f = stack[i];
      if (f.is_array)
        p += "[" + std::to_string(f.index) + "]";
      else
        p += (p.empty() ? "" : ".") + f.last_key;
    }
    return p;
  };
  auto element_done = [&stack]() {
    if (!stack.empty() && stack.back().is_array) ++stack.back().index;
  };
  using Event = nlohmann::json::parse_event_t;
  nlohmann::json::parser_callback_t cb = [&](int /*depth*/, Event event,
                                             nlohmann::json& parsed) -> bool {
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        if (stack.size() >= kMaxJsonDepth) {
          const std::string p = path(true);
          throw InputError(Category::Syntax, source,
                           p.empty()       ? "top level"
                           : p.size() > 60 ? p.substr(0, 60) + "..."
                                           : p,
                           "JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                               " levels of arrays and objects" + depth_note);
        }
        stack.emplace_back(event == Event::array_start);
        break;
      case Event::key: {
        Frame& f = stack.back();
        const std::string key = parsed.get<std::string>();
        if (std::find(f.keys.begin(), f.keys.end(), key) != f.keys.end()) {
          const std::string p = path();
          throw InputError(Category::DuplicateField, source, p.empty() ? "top level" : p,
                           "key " + quoted(key) + " appears twice in the same object");
        }
        f.keys.push_back(key);
        f.last_key = key;
        break;
      }
      case Event::object_end:
      case Event::array_end:
        stack.pop_back();
        element_done();
        break;
      case Event::value:
        element_done();
        break;
    }
    return true;
  };
  std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) throw InputError(Category::Empty, source, "", "empty file");
  try {
    return nlohmann::json::parse(text, cb);
  } catch (const nlohmann::json::parse_error& e) {
    // "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error while ..."
    std::string msg = e.what();
    std::string where = "byte " + std::to_string(e.byte);
    const std::size_t p = msg.find("parse error");
    if (p != std::string::npos) {
      msg = msg.substr(p);
      const std::size_t colon = msg.find(": ");
      if (colon != std::string::npos) {
        const std::string head = msg.substr(0, colon);
        msg = msg.substr(colon + 2);
        const std::size_t at = head.find(" at ");
        if (at != std::string::npos) where = head.substr(at + 4);
      }
      // nlohmann quotes all it has read of the current token: keep the end of long ones.
      const std::size_t lr = msg.find("last read: '");
      if (lr != std::string::npos) {
        const std::size_t b = lr + 12;
        std::size_t e2 = msg.find("'; ", b);
        if (e2 == std::string::npos) e2 = msg.size() - 1;
        if (e2 > b + 40) msg = msg.substr(0, b) + "..." + msg.substr(e2 - 37);
      }
    }
    throw InputError(Category::Syntax, source, where, "JSON " + msg);
  } catch (const nlohmann::json::out_of_range& e) {
    std::string msg = e.what();
    const std::size_t p = msg.find("] ");
    if (p != std::string::npos) msg = msg.substr(p + 2);
    throw InputError(Category::NonFinite, source, path(true), msg);
  }
}

}  // namespace softrne::io::detail
