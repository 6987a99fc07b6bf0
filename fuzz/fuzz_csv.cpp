// libFuzzer target: softrne::io::parse_csv and parse_dataset (two fixed robots,
// angles required or not) on arbitrary bytes. Only softrne::io::InputError may
// escape the parsers (fuzz_common.hpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  (void)softrne_fuzz::csv_robots();  // parse the fixed robots outside the measured runs
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  softrne_fuzz::run_csv(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
