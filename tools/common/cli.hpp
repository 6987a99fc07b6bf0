#pragma once
/// \file
/// \brief What every softrne command-line tool shares (docs/formats.md section 6): the exit
/// codes, one-line error messages `<tool>: <file>: <where>: <what>`, Ctrl-C, and the command
/// line: parsed by CLI11, adapted here to those rules (cli::App).
///
/// Usage:
/// \code
///   int main(int argc, char** argv) {
///     return softrne::cli::run("softrne-x", [&] {
///       softrne::cli::App app("softrne-x", "--in F [--threads N]", "What it does.");
///       std::string in;
///       int threads = 2;
///       app.add_option("--in", in, "input file")->type_name("F")->required();
///       app.add_integer("--threads", threads, "parallel jobs", 1, 64)->capture_default_str();
///       if (!app.parse_command_line(argc, argv)) return softrne::cli::kExitOk;  // --help
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
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <memory>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

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
  if (interrupted.load())
    throw Interrupted("interrupted (Ctrl-C) during " + what + ": nothing written");
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

/// \brief The exit codes and the error format, for the end of every tool's --help.
inline const std::string kExitStatusText =
    "exit status: 0 success; 1 the computation failed; 2 bad command line; 3 bad input file;\n"
    "4 internal error; 130 stopped by Ctrl-C. Errors are one line on stderr:\n"
    "  <tool>: <file>: <where>: <what>";

/// \brief For integer options, before CLI11 converts: decimal digits only (an optional sign),
/// leading zeros dropped. CLI11 2.1 reads integers with strtoll(..., 0), so "010" would be 8
/// and "0x10" 16, and reports "1.5" as out of range; here they are "not an integer".
inline const CLI::Validator DecimalInteger(
    [](std::string& s) {
      const std::size_t digits = !s.empty() && (s[0] == '-' || s[0] == '+') ? 1 : 0;
      if (s.size() == digits || s.find_first_not_of("0123456789", digits) != std::string::npos)
        return "not an integer: " + io::detail::quoted(s);
      const std::size_t lead = std::min(s.find_first_not_of('0', digits), s.size() - 1);
      s = (s[0] == '-' && s[lead] != '0' ? "-" : "") + s.substr(lead);
      return std::string();
    },
    "", "INTEGER");

/// \brief A finite number in [lo, hi], or (lo, hi] with FiniteNumber::open. (CLI::Range and
/// CLI::PositiveNumber accept "nan" and print their bounds with std::to_string: DBL_MAX as
/// 309 digits.)
class FiniteNumber : public CLI::Validator {
 public:
  enum Lower { closed, open };
  explicit FiniteNumber(double lo, double hi = HUGE_VAL, Lower lower = closed) {
    std::string range = (lower == open ? "> " : ">= ") + io::detail::format_double(lo);
    if (hi != HUGE_VAL) range += " and <= " + io::detail::format_double(hi);
    description(range);
    func_ = [=](std::string& s) {
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty() || *end != '\0' || !std::isfinite(v))
        return "not a finite number: " + io::detail::quoted(s);
      if (v < lo || v > hi || (lower == open && v == lo))
        return "must be " + range + " (got " + s + ")";
      return std::string();
    };
  }
};

/// \brief --help in the tools' layout, wrapped at 100 columns: the usage line first, the
/// description; each option as `--name VALUE` and its description, followed by what CLI11
/// knows of it in parentheses (its validators' descriptions, "required", its default); the
/// footer (examples, exit status) last.
class HelpFormatter : public CLI::Formatter {
 public:
  explicit HelpFormatter(std::string synopsis) : synopsis_(std::move(synopsis)) {}
  std::string make_usage(const CLI::App*, std::string name) const override {
    return "usage: " + name + " " + synopsis_ + "\n";
  }
  std::string make_help(const CLI::App* app, std::string name,
                        CLI::AppFormatMode mode) const override {
    if (mode == CLI::AppFormatMode::Sub) return CLI::Formatter::make_help(app, name, mode);
    return make_usage(app, name) + "\n" + wrap(app->get_description(), 100) + "\n" +
           make_groups(app, mode) + make_subcommands(app, mode) + "\n" + make_footer(app);
  }
  // CLI11 writes `VALUE:validators=default REQUIRED` after the name; only VALUE stays there.
  std::string make_option_opts(const CLI::Option* opt) const override {
    return opt->get_type_size() == 0 ? "" : " " + value_name(opt).first;
  }
  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string notes = opt->get_type_size() == 0 ? "" : value_name(opt).second;
    if (opt->get_required()) notes += (notes.empty() ? "" : "; ") + std::string("required");
    if (!opt->get_default_str().empty())
      notes += (notes.empty() ? "" : "; ") + ("default " + opt->get_default_str());
    return wrap(opt->get_description() + (notes.empty() ? "" : " (" + notes + ")"),
                100 - get_column_width());
  }

 private:
  /// `text` with its words on lines of at most `width` characters.
  static std::string wrap(const std::string& text, std::size_t width) {
    std::string out, line;
    std::istringstream words(text);
    for (std::string w; words >> w;) {
      if (!line.empty() && line.size() + 1 + w.size() > width) out += line + "\n", line.clear();
      line += (line.empty() ? "" : " ") + w;
    }
    return out + line;
  }
  /// CLI11's type name "VALUE:validator:validator" split into "VALUE" and "validator; validator".
  static std::pair<std::string, std::string> value_name(const CLI::Option* opt) {
    const std::string t = opt->get_type_name();
    const std::size_t colon = std::min(t.find(':'), t.size());
    std::string rest = colon < t.size() ? t.substr(colon + 1) : "";
    for (std::size_t i = rest.find(':'); i != std::string::npos; i = rest.find(':', i))
      rest.replace(i, 1, "; ");
    return {t.substr(0, colon), rest};
  }
  std::string synopsis_;
};

/// \brief A tool's command line: CLI11's App with the tools' --help layout (HelpFormatter), the
/// exit status in its footer, and parse_command_line(), which maps CLI11's errors to UsageError.
class App : public CLI::App {
 public:
  /// \param synopsis the arguments after the tool name in the usage line
  /// \param description a paragraph printed under the usage line by --help
  /// \param example lines printed under "example:" at the end of --help
  App(const std::string& tool, std::string synopsis, const std::string& description,
      const std::string& example = "")
      : CLI::App(description, tool) {
    formatter(std::make_shared<HelpFormatter>(std::move(synopsis)));
    footer((example.empty() ? "" : "example:\n" + example + "\n\n") + kExitStatusText);
    // --help acts where it is read, before the other options are checked: the help is shown
    // whatever else is wrong on the command line.
    set_help_flag();
    add_flag_callback(
        "-h,--help", [] { throw CLI::CallForHelp(); }, "print this help and exit")
        ->trigger_on_parse();
  }

  /// \brief An integer option in [lo, hi]: decimal digits only (DecimalInteger), then the
  /// range. Every integer option of the tools is made here, so none can miss the decimal
  /// check; the caller adds required() or a default text.
  template <class T, class Bound>
  CLI::Option* add_integer(const std::string& name, T& value, const std::string& help, Bound lo,
                           Bound hi) {
    return add_option(name, value, help)
        ->type_name("N")
        ->transform(DecimalInteger)
        ->check(CLI::Range(lo, hi));
  }

  /// \brief Parses argv. \return false if the tool is done and exits 0: --help was asked for
  /// (the help is then printed on stdout) or an option's callback threw CLI::Success. Every
  /// other problem is a UsageError with CLI11's one-line message, which names the option, or
  /// "unexpected argument(s): ..." if any argument is not an option of the tool (reported
  /// first: a misspelt --robot is also a missing --robot). An option with a value given twice
  /// is an error (CLI11's default), a flag given twice counts once; an empty value is an error.
  bool parse_command_line(int argc, char** argv) {
    try {
      parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
      std::cout << help();
      return false;
    } catch (const CLI::Success&) {
      return false;
    } catch (const CLI::ParseError& e) {
      const std::vector<std::string> extra = remaining();
      if (extra.empty()) throw UsageError(e.what());
      // CLI11 2.1's own message (ExtrasError) lists the arguments backwards.
      std::string args;
      for (const std::string& a : extra) args += " " + io::detail::quoted(a);
      throw UsageError((extra.size() > 1 ? "unexpected arguments:" : "unexpected argument:") +
                       args);
    }
    reject_empty_values(*this);
    return true;
  }

 private:
  static void reject_empty_values(const CLI::App& app) {
    for (const CLI::Option* o : app.get_options())
      for (const std::string& r : o->results())
        if (r.empty()) throw UsageError(o->get_name() + ": empty value");
    for (const CLI::App* group : app.get_subcommands([](const CLI::App*) { return true; }))
      reject_empty_values(*group);
  }
};

}  // namespace softrne::cli
