// libFuzzer target: softrne::io::parse_robot_json on arbitrary bytes.
// Only softrne::io::InputError may escape the parser (fuzz_common.hpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  softrne_fuzz::run_robot_json(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
