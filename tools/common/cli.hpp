#pragma once
/// \file
/// \brief What every softrne command-line tool shares (shared/spec/formats.md section 6):
/// option parsing with `--help`, one-line error messages `<tool>: <file>: <where>: <what>`,
/// and the exit codes.
///
/// Usage:
/// \code
///   int main(int argc, char** argv) {
///     return softrne::cli::run("softrne-x", [&] {
///       softrne::cli::ArgParser args("softrne-x", "--in F [--out G]", "What it does.");
///       args.option("in", "F", "input file").required();
///       args.flag("quiet", "print nothing but errors");
///       if (!args.parse(argc, argv)) return softrne::cli::kExitOk;  // --help was printed
///       const std::string in = args.value("in");
///       ...
///       return softrne::cli::kExitOk;
///     });
///   }
/// \endcode
/// Inside the body, throw io::InputError for a bad input file, cli::UsageError for a bad
/// command line and cli::Failure for a computation that failed (e.g. the integrator);
/// run() prints the one line and returns the exit code. It never lets an exception escape.

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "softrne/io/errors.hpp"

#if defined(__unix__) || defined(__APPLE__)
#include <csignal>
#include <unistd.h>
#define SOFTRNE_CLI_POSIX 1
#endif

namespace softrne::cli {

/// \brief Exit codes of the tools (all < 128, so never confused with a signal, except the
/// one that reports Ctrl-C the way a shell does).
enum ExitCode : int {
  kExitOk = 0,        ///< success
  kExitFailure = 1,   ///< the computation failed (integrator failure, fit diverged, ...)
  kExitUsage = 2,     ///< bad command line: unknown option, missing or malformed value
  kExitInput = 3,     ///< a bad input file (missing, unreadable, malformed) or unwritable output
  kExitInternal = 4,  ///< an unexpected internal error (a bug: please report it)
  /// Stopped by Ctrl-C (SIGINT) after a clean stop: nothing was written. 128 + SIGINT, as a
  /// shell reports a command killed by Ctrl-C, so scripts treat it alike.
  kExitInterrupted = 130,
};

/// \brief Set by Ctrl-C (SIGINT) once stop_on_interrupt() ran; point the simulator's
/// `CvodeOptions::stop` at it, so that a long fit or loop ends within one simulation step.
inline std::atomic<bool> interrupted{false};

/// \brief A stop on request (Ctrl-C); run() prints the message and returns kExitInterrupted.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief From now on the first Ctrl-C sets `interrupted` (the tool stops cleanly and says
/// so); a second one kills the process as usual.
inline void stop_on_interrupt() {
#ifdef SOFTRNE_CLI_POSIX
  std::signal(SIGINT, [](int) {
    interrupted.store(true);
    std::signal(SIGINT, SIG_DFL);
  });
#endif
}

/// \brief Throws Interrupted if Ctrl-C was pressed: call after a long computation, before
/// writing its results (which may be incomplete).
inline void throw_if_interrupted(const std::string& what) {
  if (interrupted.load()) throw Interrupted("interrupted (Ctrl-C) during " + what + ": nothing written");
}

/// \brief A bad command line; `what()` is the message after `<tool>: `.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief A computation that failed on valid input; `what()` is the message after `<tool>: `
/// (name the file it concerns first, e.g. "test.csv: CVODE failed at t = 3.2 s: ...").
class Failure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief Prints `<tool>: <message>` as exactly one line on stderr (control characters
/// escaped).
inline void print_error(const std::string& tool, const std::string& message) {
  std::cout.flush();
  std::cerr << tool << ": " << io::detail::one_line(message) << std::endl;
}

/// \brief Runs a tool's body and turns every exception into one line on stderr and an exit
/// code (see ExitCode). `body` returns the exit code on success. SIGPIPE is ignored, so that a
/// closed pipe on stdout (`softrne-sim ... --out - | head`) is a write error with a message,
/// not a death by signal.
template <class Body>
int run(const std::string& tool, Body&& body) noexcept {
#ifdef SOFTRNE_CLI_POSIX
  std::signal(SIGPIPE, SIG_IGN);
#endif
  try {
    try {
      return std::forward<Body>(body)();
    } catch (const io::InputError& e) {
      print_error(tool, e.what());
      return kExitInput;
    } catch (const UsageError& e) {
      print_error(tool, std::string(e.what()) + " (see --help)");
      return kExitUsage;
    } catch (const Interrupted& e) {
      print_error(tool, e.what());
      return kExitInterrupted;
    } catch (const Failure& e) {
      if (interrupted.load()) {  // a run that failed because it was stopped
        print_error(tool, "interrupted (Ctrl-C): nothing written");
        return kExitInterrupted;
      }
      print_error(tool, e.what());
      return kExitFailure;
    } catch (const std::bad_alloc&) {
      print_error(tool, "out of memory");
      return kExitInternal;
    } catch (const std::exception& e) {
      if (interrupted.load()) {  // whatever a stopped computation threw
        print_error(tool, "interrupted (Ctrl-C): nothing written");
        return kExitInterrupted;
      }
      print_error(tool, std::string("internal error: ") + e.what());
      return kExitInternal;
    } catch (...) {
      print_error(tool, "internal error: unknown exception");
      return kExitInternal;
    }
  } catch (...) {  // printing itself failed
    return kExitInternal;
  }
}

/// \brief True if stderr is a terminal (for progress indicators).
inline bool stderr_is_terminal() {
#ifdef SOFTRNE_CLI_POSIX
  return ::isatty(STDERR_FILENO) != 0;
#else
  return false;
#endif
}

/// \brief Long options `--name value`, `--name=value` and flags `--name`, plus `--help`/`-h`.
/// Unknown options, positional arguments, a missing value and an option given twice are
/// UsageErrors.
class ArgParser {
 public:
  /// \param synopsis the arguments after the tool name in the usage line
  /// \param description a paragraph printed under the usage line by --help
  ArgParser(std::string tool, std::string synopsis, std::string description)
      : tool_(std::move(tool)),
        synopsis_(std::move(synopsis)),
        description_(std::move(description)) {}

  /// \brief Handle to refine the option just declared.
  class OptionRef {
   public:
    OptionRef(ArgParser& p, std::size_t i) : p_(&p), i_(i) {}
    OptionRef& required() {
      p_->opts_[i_].required = true;
      return *this;
    }
    OptionRef& default_value(std::string v) {
      p_->opts_[i_].default_text = std::move(v);
      return *this;
    }

   private:
    ArgParser* p_;
    std::size_t i_;
  };

  /// \brief An option with a value, `--name VALUE`.
  OptionRef option(const std::string& name, const std::string& value_name,
                   const std::string& help) {
    opts_.push_back(Option{name, value_name, help, false, false, "", false, ""});
    return OptionRef(*this, opts_.size() - 1);
  }
  /// \brief A flag without a value, `--name`.
  OptionRef flag(const std::string& name, const std::string& help) {
    opts_.push_back(Option{name, "", help, true, false, "", false, ""});
    return OptionRef(*this, opts_.size() - 1);
  }
  /// \brief A paragraph appended to --help (examples, exit codes).
  void epilog(std::string text) { epilog_ = std::move(text); }

  /// \brief Parses argv. \return false if --help was asked for (the help is then printed on
  /// stdout and the tool should exit 0). Throws UsageError.
  bool parse(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i] ? argv[i] : "";
      if (a == "--help" || a == "-h") {
        std::cout << help();
        return false;
      }
    }
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i] ? argv[i] : "";
      if (a.size() < 3 || a.compare(0, 2, "--") != 0) {
        if (!a.empty() && a[0] == '-' && a != "-")
          throw UsageError("unknown option " + io::detail::quoted(a));
        throw UsageError("unexpected argument " + io::detail::quoted(a) +
                         " (options are given as --name value)");
      }
      std::string name = a.substr(2), value;
      bool has_inline_value = false;
      if (const auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_inline_value = true;
      }
      Option* o = find(name);
      if (!o)
        throw UsageError("unknown option " + io::detail::quoted("--" + name) + suggestion(name));
      if (o->seen) throw UsageError("option --" + name + " given twice");
      o->seen = true;
      if (o->is_flag) {
        if (has_inline_value) throw UsageError("option --" + name + " takes no value");
        continue;
      }
      if (!has_inline_value) {
        if (i + 1 >= argc)
          throw UsageError("option --" + name + " needs a value (" + o->value_name + ")");
        value = argv[++i] ? argv[i] : "";
      }
      if (value.empty()) throw UsageError("option --" + name + ": empty value");
      o->value = value;
    }
    for (const auto& o : opts_)
      if (o.required && !o.seen)
        throw UsageError("missing required option --" + o.name + " " + o.value_name);
    return true;
  }

  /// \brief True if the option or flag was given.
  bool has(const std::string& name) const { return get(name).seen; }
  /// \brief The option's value, or its default text ("" if none) when it was not given.
  std::string value(const std::string& name) const {
    const Option& o = get(name);
    return o.seen ? o.value : o.default_text;
  }
  /// \brief The option's value as a finite number in [lo, hi]; `fallback` if not given.
  double number(const std::string& name, double fallback, double lo = -HUGE_VAL,
                double hi = HUGE_VAL, bool lo_open = false) const {
    const Option& o = get(name);
    if (!o.seen) return fallback;
    const std::string& s = o.value;
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
      throw UsageError("option --" + name + ": not a finite number: " + io::detail::quoted(s));
    if (v < lo || v > hi || (lo_open && v == lo)) {
      std::string range =
          lo_open ? "> " + io::detail::format_double(lo) : ">= " + io::detail::format_double(lo);
      if (lo == -HUGE_VAL)
        range = "<= " + io::detail::format_double(hi);
      else if (hi != HUGE_VAL)
        range += " and <= " + io::detail::format_double(hi);
      throw UsageError("option --" + name + ": must be " + range + " (got " + s + ")");
    }
    return v;
  }
  /// \brief The option's value as an integer in [lo, hi]; `fallback` if not given.
  long integer(const std::string& name, long fallback, long lo, long hi) const {
    const Option& o = get(name);
    if (!o.seen) return fallback;
    errno = 0;
    char* end = nullptr;
    const long v = std::strtol(o.value.c_str(), &end, 10);
    if (end == o.value.c_str() || *end != '\0' || errno == ERANGE)
      throw UsageError("option --" + name + ": not an integer: " + io::detail::quoted(o.value));
    if (v < lo || v > hi)
      throw UsageError("option --" + name + ": must be in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "] (got " + o.value + ")");
    return v;
  }
  /// \brief The option's value, which must be one of `choices`; `fallback` if not given.
  std::string choice(const std::string& name, const std::vector<std::string>& choices,
                     const std::string& fallback) const {
    const Option& o = get(name);
    if (!o.seen) return fallback;
    for (const auto& c : choices)
      if (c == o.value) return c;
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    throw UsageError("option --" + name + ": unknown value " + io::detail::quoted(o.value) +
                     " (one of " + list + ")");
  }

  /// \brief The --help text (option descriptions wrapped at 100 columns).
  std::string help() const {
    std::string s = "usage: " + tool_ + " " + synopsis_ + "\n\n" + description_ + "\n\noptions:\n";
    std::size_t width = 10;
    auto left = [](const Option& o) {
      return "--" + o.name + (o.is_flag ? std::string() : " " + o.value_name);
    };
    for (const auto& o : opts_) width = std::max(width, left(o).size());
    auto add = [&](const std::string& l, const std::string& text) {
      std::string line = "  " + l;
      line.resize(width + 4, ' ');
      s += wrap(line, text, width + 4, 100);
    };
    for (const auto& o : opts_) {
      std::string text = o.help;
      if (o.required) text += " (required)";
      if (!o.default_text.empty()) text += " [default: " + o.default_text + "]";
      add(left(o), text);
    }
    add("--help", "print this help and exit");
    if (!epilog_.empty()) s += "\n" + epilog_ + "\n";
    return s;
  }

  /// \brief Standard paragraph on exit codes and error messages, for epilogs.
  static std::string exit_code_text() {
    return "exit status: 0 success; 1 the computation failed; 2 bad command line; 3 bad input\n"
           "file; 4 internal error. Errors are one line on stderr:\n"
           "  <tool>: <file>: <where>: <what>";
  }

 private:
  struct Option {
    std::string name, value_name, help;
    bool is_flag = false;
    bool required = false;
    std::string default_text;
    bool seen = false;
    std::string value;
  };

  Option* find(const std::string& name) {
    for (auto& o : opts_)
      if (o.name == name) return &o;
    return nullptr;
  }
  const Option& get(const std::string& name) const {
    for (const auto& o : opts_)
      if (o.name == name) return o;
    throw std::logic_error("ArgParser: option --" + name + " was not declared");
  }
  std::string suggestion(const std::string& name) const {
    std::string best;
    std::size_t best_d = 3;
    for (const auto& o : opts_) {
      const std::size_t d = edit_distance(name, o.name);
      if (d < best_d) best_d = d, best = o.name;
    }
    return best.empty() ? std::string() : "; did you mean --" + best + "?";
  }
  static std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      cur[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j)
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
      std::swap(prev, cur);
    }
    return prev[b.size()];
  }

  /// `first` (already `indent` wide) followed by `text` wrapped at `columns`, continuation
  /// lines indented by `indent`.
  static std::string wrap(std::string first, const std::string& text, std::size_t indent,
                          std::size_t columns) {
    std::string out, line = std::move(first);
    std::size_t pos = 0;
    bool line_empty = true;
    while (pos < text.size()) {
      const std::size_t end = std::min(text.find(' ', pos), text.size());
      const std::string word = text.substr(pos, end - pos);
      pos = end + 1;
      if (word.empty()) continue;
      if (!line_empty && line.size() + 1 + word.size() > columns) {
        out += line + "\n";
        line = std::string(indent, ' ');
        line_empty = true;
      }
      line += (line_empty ? "" : " ") + word;
      line_empty = false;
    }
    return out + line + "\n";
  }

  std::string tool_, synopsis_, description_, epilog_;
  std::vector<Option> opts_;
};

/// \brief Refuses (UsageError) an output option that names one of the input files: a tool
/// never overwrites what it reads. Files are compared as files (std::filesystem::equivalent:
/// `./run.csv`, `run.csv` and a link to it are the same). Options not given are skipped.
inline void check_outputs_are_not_inputs(const ArgParser& args, const std::vector<std::string>& inputs,
                                         const std::vector<std::string>& outputs) {
  namespace fs = std::filesystem;
  for (const auto& out : outputs) {
    if (!args.has(out) || args.value(out) == "-") continue;
    for (const auto& in : inputs) {
      if (!args.has(in)) continue;
      std::error_code ec;
      if (fs::equivalent(fs::path(args.value(out)), fs::path(args.value(in)), ec) && !ec)
        throw UsageError("option --" + out + ": " + args.value(out) + " is the input given to --" + in +
                         "; refusing to overwrite an input");
    }
  }
}

}  // namespace softrne::cli
