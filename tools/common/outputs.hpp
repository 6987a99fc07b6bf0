#pragma once
/// \file
/// \brief No tool writes over one of its own inputs (docs/formats.md section 6). The other half
/// of the rule on files, every output written to a temporary file and renamed when complete,
/// is the library's writers' (io::detail::write_text_file).

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "common/cli.hpp"

namespace softrne::cli {

/// \brief A file named on the command line: the option ("--out") and its value ("" if not given).
struct FileOption {
  std::string option;
  std::string path;
};

/// \brief Refuses (UsageError) an output that is one of the inputs, compared as files
/// (std::filesystem::equivalent: `./run.csv`, `run.csv` and a link to it are the same).
/// Options not given ("") and stdout ("-") are skipped.
inline void check_outputs_are_not_inputs(const std::vector<FileOption>& inputs,
                                         const std::vector<FileOption>& outputs) {
  namespace fs = std::filesystem;
  for (const auto& out : outputs) {
    if (out.path.empty() || out.path == "-") continue;
    for (const auto& in : inputs) {
      std::error_code ec;
      if (!in.path.empty() && fs::equivalent(fs::path(out.path), fs::path(in.path), ec) && !ec)
        throw UsageError(out.option + ": " + out.path + " is the input given to " + in.option +
                         "; refusing to overwrite an input");
    }
  }
}

}  // namespace softrne::cli
