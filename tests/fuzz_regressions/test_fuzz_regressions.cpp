// Inputs found by fuzzing (fuzz/regressions/) and the fuzzers' seed corpus
// (fuzz/corpus/*/), replayed through the same calls as the fuzz targets
// (fuzz/fuzz_common.hpp): each parser must accept the input or throw
// softrne::io::InputError; any other exception fails the test, and a crash or a
// sanitizer report (CI runs the tests under ASan/UBSan) fails the binary.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../../fuzz/fuzz_common.hpp"

namespace fs = std::filesystem;
namespace sio = softrne::io;

namespace {

const fs::path kFuzzDir = fs::path(SOFTRNE_DATA_DIR) / ".." / ".." / "fuzz";

std::string slurp(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Regular files under `dir` (recursively), sorted, without README files.
std::vector<fs::path> files_under(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string().rfind("README", 0) != 0)
      out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

/// Every parser on `text`: InputError or success only.
void replay(const std::string& text, const std::string& label) {
  SCOPED_TRACE(label);
  try {
    softrne_fuzz::run_robot_json(text);
  } catch (const std::exception& e) {
    ADD_FAILURE() << label << ": parse_robot_json threw a non-InputError: " << e.what();
  }
  try {
    softrne_fuzz::run_csv(text);
  } catch (const std::exception& e) {
    ADD_FAILURE() << label << ": parse_csv/parse_dataset threw a non-InputError: " << e.what();
  }
}

std::string nested_arrays(std::size_t depth) {
  return std::string(depth, '[') + std::string(depth, ']');
}

}  // namespace

TEST(FuzzRegressions, FolderExists) {
  // The README at least: a moved folder must not silently turn the replay into a no-op.
  EXPECT_TRUE(fs::exists(kFuzzDir / "regressions" / "README.md")) << kFuzzDir;
  EXPECT_GE(files_under(kFuzzDir / "corpus").size(), 10u);
}

TEST(FuzzRegressions, RegressionInputsGiveInputErrorOrSuccess) {
  for (const auto& f : files_under(kFuzzDir / "regressions")) replay(slurp(f), f.string());
}

TEST(FuzzRegressions, SeedCorpusGivesInputErrorOrSuccess) {
  for (const auto& f : files_under(kFuzzDir / "corpus")) replay(slurp(f), f.string());
}

TEST(FuzzRegressions, SeedRobotsOfTheCsvTargetAreValid) {
  ASSERT_EQ(softrne_fuzz::csv_robots().size(), 2u);
  EXPECT_EQ(sio::num_pressure_columns(softrne_fuzz::csv_robots()[0]), 12u);
  EXPECT_EQ(sio::num_pressure_columns(softrne_fuzz::csv_robots()[1]), 3u);
  EXPECT_NO_THROW((void)sio::parse_dataset(slurp(kFuzzDir / "corpus/csv/arm-a-1-train-head.csv"),
                                           "train.csv", softrne_fuzz::csv_robots()[0], true));
  EXPECT_NO_THROW((void)sio::parse_dataset(slurp(kFuzzDir / "corpus/csv/hybrid-crlf-bom.csv"),
                                           "hybrid.csv", softrne_fuzz::csv_robots()[1], true));
}

// Regression: JSON nested 100000 levels deep overflowed the stack (segfault, also in
// Release builds) in detail::describe -> nlohmann::json::dump, reached from
// require_object("top level") in robot_from_json.
TEST(FuzzRegressions, DeeplyNestedJsonIsASyntaxError) {
  for (const std::size_t depth : {65u, 1000u, 100000u, 1000000u}) {
    SCOPED_TRACE(depth);
    try {
      (void)sio::parse_robot_json(nested_arrays(depth), "deep.json");
      ADD_FAILURE() << "no error";
    } catch (const sio::InputError& e) {
      EXPECT_EQ(e.category(), sio::Category::Syntax) << e.what();
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("deep.json: ", 0), 0u) << msg;
      EXPECT_NE(msg.find("nested deeper than 64"), std::string::npos) << msg;
      EXPECT_LT(msg.size(), 200u) << msg;
    }
  }
  // The same inside a field, with objects.
  std::string text = R"({"format": "softrne-robot/1", "gravity": [0, 0, 9.81], "segments": [)"
                     R"({"type": "cc_joint", "mass": )";
  for (int i = 0; i < 5000; ++i) text += "{\"a\": ";
  text += "1" + std::string(5000, '}') + "}]}";
  try {
    (void)sio::parse_robot_json(text, "deep.json");
    ADD_FAILURE() << "no error";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::Syntax) << e.what();
    EXPECT_NE(std::string(e.what()).find("deep.json: segments[0].mass.a.a"), std::string::npos)
        << e.what();
  }
}

TEST(FuzzRegressions, NestingUpToTheLimitIsParsed) {
  // 64 levels parse; the document is then refused for what it is (not an object).
  try {
    (void)sio::parse_robot_json(nested_arrays(64), "deep.json");
    ADD_FAILURE() << "no error";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::WrongType) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected a JSON object, got array"), std::string::npos)
        << e.what();
  }
}

// robot_from_json takes JSON parsed elsewhere (e.g. a loop report): its messages must
// not recurse over a deep value either.
TEST(FuzzRegressions, DeepJsonValueFromElsewhereGivesInputError) {
  // Built in place (copying or an initializer list would recurse over the depth).
  nlohmann::json deep = nlohmann::json::array();
  nlohmann::json* innermost = &deep;
  for (int i = 0; i < 200000; ++i) {
    innermost->push_back(nlohmann::json::array());
    innermost = &innermost->back();
  }
  try {
    (void)sio::robot_from_json(deep, "report.json", "fitted_robot.");
    ADD_FAILURE() << "no error";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::WrongType) << e.what();
    EXPECT_NE(std::string(e.what()).find("nested more than 16 levels"), std::string::npos)
        << e.what();
  }
  nlohmann::json robot = nlohmann::json::parse(softrne_fuzz::kHybrid);
  robot["segments"][0]["mass"] = std::move(deep);
  try {
    (void)sio::robot_from_json(robot, "report.json");
    ADD_FAILURE() << "no error";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::WrongType) << e.what();
    EXPECT_NE(std::string(e.what()).find("segments[0] 'joint1': field 'mass': expected a number"),
              std::string::npos)
        << e.what();
  }
}
