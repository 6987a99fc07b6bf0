#pragma once
// Files of the io tests: a path of this process's own in the system's temporary directory, and
// a whole file read back.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

namespace softrne_test {

inline std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("softrne_io_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

inline std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace softrne_test
