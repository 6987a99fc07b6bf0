// csv.hpp must compile on its own: it is included first.
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "temp_files.hpp"

namespace sio = softrne::io;

namespace {

const char* const kArmDir = SOFTRNE_DATA_DIR "/arm-a-1";

using softrne_test::slurp;
using softrne_test::temp_path;

/// cc joint "joint1" (4 chambers), rigid link, revolute joint "wrist".
const sio::RobotSpec& small_robot() {
  static const sio::RobotSpec r = sio::parse_robot_json(R"({
    "format": "softrne-robot/1", "name": "small", "gravity": [0, 0, 9.81],
    "segments": [
      {"type": "cc_joint", "name": "joint1", "mass": 0.8, "height": 0.2, "diameter": 0.2,
       "chamber_distance": 0.06, "chamber_radius": 0.03, "stiffness": [40, 40], "damping": [3, 3]},
      {"type": "rigid_link", "name": "link1", "mass": 1.5, "length": 0.15,
       "com": [0, 0, 0.075], "inertia": [0.0052, 0.0052, 0.0048, 0, 0, 0]},
      {"type": "revolute_joint", "name": "wrist", "axis": [0, 0, 1], "stiffness": 0, "damping": 0.1}
    ]})",
                                                        "small.json");
  return r;
}

const std::string kHeader = "t,p1_0,p1_1,p1_2,p1_3,u1,v1,qwrist\n";
const std::string kRow0 = "0.00,100,200,300,400,0.1,0.2,0.3\n";
const std::string kRow1 = "0.01,101,201,301,401,0.11,0.21,0.31\n";
const std::string kRow2 = "0.02,102,202,302,402,0.12,0.22,0.32\n";
const std::string kGood = "# a comment\n" + kHeader + kRow0 + kRow1 + kRow2;

enum class Reader { Dataset, DatasetNeedAngles, Table };

struct BadCsvCase {
  std::string name;
  std::string text;
  Reader reader;
  sio::Category category;
  std::vector<std::string> expect;  // substrings of the message (besides the source name)
};

std::string replace_once(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  if (p == std::string::npos) throw std::logic_error("test bug: '" + from + "' not found");
  return s.replace(p, from.size(), to);
}

std::vector<BadCsvCase> bad_csv_cases() {
  using C = sio::Category;
  using R = Reader;
  const std::string long_line =
      kHeader + kRow0 + "0.01," + std::string((1u << 20) + 10, '1') + "\n";
  return {
      {"empty_file", "", R::Dataset, C::Empty, {"empty file"}},
      {"only_bom_and_blank", "\xEF\xBB\xBF\r\n\r\n", R::Dataset, C::Empty, {"empty"}},
      {"only_comments", "# one\n# two\n", R::Dataset, C::Empty, {"only comments"}},
      {"missing_t",
       replace_once(kGood, "t,", "time,"),
       R::Dataset,
       C::MissingColumn,
       {"line 2", "'t'"}},
      {"missing_pressure",
       replace_once(kGood, "p1_2,", "px,"),
       R::Dataset,
       C::MissingColumn,
       {"'p1_2'"}},
      {"duplicate_column",
       replace_once(kGood, "v1,", "u1,"),
       R::Dataset,
       C::DuplicateColumn,
       {"'u1'", "line 2"}},
      {"duplicate_ignored_column",
       replace_once(kGood, "qwrist", "t"),
       R::Dataset,
       C::DuplicateColumn,
       {"'t'"}},
      {"partial_angles",
       replace_once(kGood, "qwrist", "extra"),
       R::Dataset,
       C::MissingColumn,
       {"'qwrist'", "all present or all absent"}},
      {"angles_required",
       "t,p1_0,p1_1,p1_2,p1_3\n0,1,2,3,4\n0.01,1,2,3,4\n",
       R::DatasetNeedAngles,
       C::MissingColumn,
       {"'u1'", "required"}},
      {"unexpected_pressure_joint",
       replace_once(kGood, "qwrist", "p2_0"),
       R::Dataset,
       C::UnexpectedColumn,
       {"'p2_0'", "disagree"}},
      {"unexpected_chamber",
       replace_once(kGood, "qwrist", "p1_4"),
       R::Dataset,
       C::UnexpectedColumn,
       {"'p1_4'"}},
      {"unexpected_angle",
       replace_once(kGood, "qwrist", "u2"),
       R::Dataset,
       C::UnexpectedColumn,
       {"'u2'"}},
      {"row_too_short",
       kHeader + kRow0 + "0.01,101,201,301,401,0.11,0.21\n" + kRow2,
       R::Dataset,
       C::BadRowLength,
       {"line 3", "expected 8 cells", "got 7"}},
      {"row_trailing_comma",
       kHeader + kRow0 + kRow1 + "0.02,102,202,302,402,0.12,0.22,0.32,\n",
       R::Dataset,
       C::BadRowLength,
       {"line 4", "got 9"}},
      {"comma_decimal",
       kHeader + kRow0 + "0,01,101,201,301,401,0.11,0.21,0.31\n",
       R::Dataset,
       C::BadRowLength,
       {"line 3"}},
      {"semicolon_separated",
       "t;p1_0;p1_1;p1_2;p1_3\n0;1;2;3;4\n",
       R::Dataset,
       C::MissingColumn,
       {"'t'", "separated by ','"}},
      {"not_a_number",
       replace_once(kGood, "0.21,", "abc,"),
       R::Dataset,
       C::BadNumber,
       {"line 4, column 'v1': not a number: 'abc'"}},
      {"trailing_garbage",
       replace_once(kGood, "0.11,", "0.11x,"),
       R::Dataset,
       C::BadNumber,
       {"column 'u1'", "'0.11x'"}},
      {"hex_number",
       replace_once(kGood, "201,", "0x10,"),
       R::Dataset,
       C::BadNumber,
       {"column 'p1_1'"}},
      {"empty_cell",
       replace_once(kGood, "301,", ","),
       R::Dataset,
       C::BadNumber,
       {"line 4, column 'p1_2'", "empty cell"}},
      {"nan_cell",
       replace_once(kGood, "0.31", "NaN"),
       R::Dataset,
       C::NonFinite,
       {"line 4, column 'qwrist'"}},
      {"inf_cell",
       replace_once(kGood, "401", "-inf"),
       R::Dataset,
       C::NonFinite,
       {"line 4, column 'p1_3'"}},
      {"overflow_cell",
       replace_once(kGood, "102", "1e999"),
       R::Dataset,
       C::NonFinite,
       {"line 5, column 'p1_0'"}},
      {"nan_time", replace_once(kGood, "0.01,", "nan,"), R::Dataset, C::NonFinite, {"column 't'"}},
      {"time_repeated",
       kHeader + kRow0 + kRow1 + replace_once(kRow2, "0.02", "0.01"),
       R::Dataset,
       C::NonIncreasingTime,
       {"line 4", "0.01 after 0.01 on line 3"}},
      {"time_decreasing",
       "# c\n" + kHeader + kRow1 + kRow0,
       R::Dataset,
       C::NonIncreasingTime,
       {"line 4"}},
      {"one_row", kHeader + kRow0, R::Dataset, C::TooFewRows, {"1 data row", "at least 2"}},
      {"header_only", kHeader, R::Dataset, C::TooFewRows, {"0 data rows"}},
      {"blank_line_inside",
       kHeader + kRow0 + "\n" + kRow1,
       R::Dataset,
       C::BadRowLength,
       {"line 3", "blank line"}},
      {"line_too_long", long_line, R::Dataset, C::LineTooLong, {"line 3", "1048576"}},
      {"table_not_a_number", "a,b\n1,2\n3,x\n", R::Table, C::BadNumber, {"line 3, column 'b'"}},
      {"table_duplicate",
       "a,b,a\n1,2,3\n",
       R::Table,
       C::DuplicateColumn,
       {"'a'", "columns 1 and 3"}},
      {"table_row_length", "a,b\n1,2\n3\n", R::Table, C::BadRowLength, {"line 3"}},
  };
}

void expect_small_good(const sio::Dataset& d) {
  ASSERT_EQ(d.t.size(), 3);
  EXPECT_EQ(d.t[1], 0.01);
  ASSERT_EQ(d.pressures.rows(), 3);
  ASSERT_EQ(d.pressures.cols(), 4);
  EXPECT_EQ(d.pressures(2, 3), 402.0);
  EXPECT_EQ(d.pressures(0, 0), 100.0);
  ASSERT_TRUE(d.has_angles);
  ASSERT_EQ(d.angles.cols(), 3);
  EXPECT_EQ(d.angles(1, 0), 0.11);
  EXPECT_EQ(d.angles(2, 2), 0.32);
}

}  // namespace

TEST(IoCsv, ReadsArmATrainAndTest) {
  const sio::RobotSpec robot = sio::read_robot_json(std::string(kArmDir) + "/robot.json");
  const sio::Dataset train = sio::read_dataset(std::string(kArmDir) + "/train.csv", robot, true);
  // 3 comment lines, the header, then 1000 rows: t = 0.00 .. 9.99 (10 s at 100 Hz).
  EXPECT_EQ(train.t.size(), 1000);
  EXPECT_EQ(train.t[999], 9.99);
  EXPECT_EQ(train.pressures.rows(), 1000);
  EXPECT_EQ(train.pressures.cols(), 12);
  EXPECT_EQ(train.angles.rows(), 1000);
  EXPECT_EQ(train.angles.cols(), 6);
  EXPECT_TRUE(train.has_angles);
  EXPECT_EQ(train.t[0], 0.0);
  EXPECT_EQ(train.t[1], 0.01);
  EXPECT_EQ(train.pressures(0, 0), -33.0);
  EXPECT_EQ(train.pressures(0, 11), -353.2);
  EXPECT_EQ(train.pressures(1, 0), 26532.9);
  EXPECT_EQ(train.angles(0, 0), 0.001327);
  EXPECT_EQ(train.angles(0, 5), 0.005659);
  EXPECT_EQ(train.angles(1, 5), -0.012318);
  EXPECT_EQ(train.pressure_names.size(), 12u);
  EXPECT_EQ(train.angle_names.back(), "v3");

  const sio::Dataset test = sio::read_dataset(std::string(kArmDir) + "/test.csv", robot, false);
  EXPECT_EQ(test.t.size(), 1400);  // t = 0.00 .. 13.99
  EXPECT_EQ(test.t[1399], 13.99);
  EXPECT_EQ(test.pressures.cols(), 12);
  EXPECT_EQ(test.angles.cols(), 6);
  EXPECT_TRUE(test.has_angles);
  for (Eigen::Index i = 1; i < test.t.size(); ++i) ASSERT_GT(test.t[i], test.t[i - 1]);

  const sio::Table table = sio::read_csv(std::string(kArmDir) + "/train.csv");
  EXPECT_EQ(table.header.size(), 19u);
  EXPECT_EQ(table.values.rows(), 1000);
  EXPECT_EQ(table.values.cols(), 19);
  EXPECT_EQ(sio::find_column(table, "u1"), 13);
  EXPECT_EQ(sio::find_column(table, "nope"), -1);
  EXPECT_EQ(table.values(0, 13), 0.001327);
}

TEST(IoCsv, PressureFileWithoutAngles) {
  const std::string text = "t,p1_0,p1_1,p1_2,p1_3\n0,1,2,3,4\n0.01,1,2,3,4\n";
  const sio::Dataset d = sio::parse_dataset(text, "p.csv", small_robot(), false);
  EXPECT_FALSE(d.has_angles);
  EXPECT_EQ(d.angles.rows(), 2);
  EXPECT_EQ(d.angles.cols(), 0);
  EXPECT_EQ(d.pressures.cols(), 4);
}

TEST(IoCsv, LenientWhereHarmless) {
  // BOM, CRLF, comments, blank lines before the header and at the end, spaces,
  // quoted header names, reordered columns, '+' signs, unknown and unnamed columns
  // (even non-numeric ones: they are not parsed).
  const std::string text =
      "\xEF\xBB\xBF# exported by the rig\r\n\r\n"
      "\"idx\", qwrist ,u1,v1,mode,t,p1_3,p1_2,p1_1,p1_0,\r\n"
      "0, 0.3,0.1,0.2,idle,0.00,400,300,200,100,\r\n"
      "1,0.31,0.11,0.21,run,+0.01,401,301,201,101,x\r\n"
      "# a comment in the data is skipped\r\n"
      "2,0.32,0.12,0.22,run,0.02,402,302,202,102,\r\n"
      "\r\n\r\n";
  expect_small_good(sio::parse_dataset(text, "lenient.csv", small_robot(), true));
  // No final newline, scientific notation.
  const std::string text2 = kHeader + kRow0 + kRow1 + "2e-2,1.02e2,202,302,402,0.12,0.22,0.32";
  expect_small_good(sio::parse_dataset(text2, "nofinal.csv", small_robot(), true));
}

TEST(IoCsv, IrregularTimeAllowed) {
  const std::string text = kHeader + kRow0 + "0.001,1,2,3,4,0,0,0\n1.5,1,2,3,4,0,0,0\n";
  const sio::Dataset d = sio::parse_dataset(text, "irregular.csv", small_robot(), true);
  EXPECT_EQ(d.t[2], 1.5);
}

TEST(IoCsv, CustomChamberCount) {
  sio::RobotSpec r = small_robot();
  auto& j = std::get<sio::CCJointSpec>(r.segments[0]);
  j.pressure_to_torque.resize(2, 3);
  j.pressure_to_torque << 1, -0.5, -0.5, 0, 0.8, -0.8;
  j.custom_pressure_map = true;
  const std::string text = "t,p1_0,p1_1,p1_2\n0,1,2,3\n0.1,4,5,6\n";
  const sio::Dataset d = sio::parse_dataset(text, "three.csv", r, false);
  EXPECT_EQ(d.pressures.cols(), 3);
  EXPECT_EQ(d.pressures(1, 2), 6.0);
  // A fourth chamber column means that robot and data disagree.
  EXPECT_THROW(
      sio::parse_dataset("t,p1_0,p1_1,p1_2,p1_3\n0,1,2,3,4\n0.1,4,5,6,7\n", "four.csv", r, false),
      sio::InputError);
}

TEST(IoCsv, MalformedInputsTable) {
  const auto cases = bad_csv_cases();
  EXPECT_GE(cases.size(), 30u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string source = "bad_" + c.name + ".csv";
    try {
      switch (c.reader) {
        case Reader::Dataset:
          (void)sio::parse_dataset(c.text, source, small_robot(), false);
          break;
        case Reader::DatasetNeedAngles:
          (void)sio::parse_dataset(c.text, source, small_robot(), true);
          break;
        case Reader::Table:
          (void)sio::parse_csv(c.text, source);
          break;
      }
      ADD_FAILURE() << c.name << ": no error";
    } catch (const sio::InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(e.category(), c.category)
          << c.name << ": got " << sio::to_string(e.category()) << ": " << msg;
      EXPECT_EQ(msg.rfind(source + ": ", 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_LT(msg.size(), 400u) << msg;
      for (const auto& s : c.expect)
        EXPECT_NE(msg.find(s), std::string::npos) << "'" << s << "' not in: " << msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << c.name << ": wrong exception type: " << e.what();
    }
  }
}

TEST(IoCsv, MissingFile) {
  try {
    (void)sio::read_dataset("/nonexistent/train.csv", small_robot(), true);
    FAIL();
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::FileNotFound);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/train.csv"), std::string::npos);
  }
}

TEST(IoCsv, TrajectoryRoundTripIsExact) {
  const Eigen::Index N = 200;
  Eigen::VectorXd t(N);
  Eigen::MatrixXd q(N, 3);
  double acc = 0.0;
  for (Eigen::Index i = 0; i < N; ++i) {
    acc += 0.001 + 1e-7 * static_cast<double>(i % 7) + 1.0 / 3.0 * 1e-3;  // irregular, not decimal
    t[i] = acc;
    q(i, 0) = std::sin(0.37 * static_cast<double>(i)) / 3.0;
    q(i, 1) = 1e-300 * static_cast<double>(i) - 0.1;
    q(i, 2) = static_cast<double>(i) * 1e12 + 0.1;
  }
  const std::vector<std::string> names{"u1", "v1", "qwrist"};
  const std::string path = temp_path("traj.csv");
  sio::write_trajectory_csv(path, t, q, names);
  EXPECT_EQ(slurp(path).rfind("t,u1,v1,qwrist\n", 0), 0u);
  const sio::Table back = sio::read_csv(path);
  EXPECT_EQ(back.header, (std::vector<std::string>{"t", "u1", "v1", "qwrist"}));
  ASSERT_EQ(back.values.rows(), N);
  EXPECT_EQ(back.values.col(0), t);        // bit for bit
  EXPECT_EQ(back.values.rightCols(3), q);  // bit for bit
  std::filesystem::remove(path);
}

TEST(IoCsv, WriteCsvRoundTripWithComments) {
  sio::Table table;
  table.header = {"t", "p1_0", "p1_1", "p1_2", "p1_3"};
  table.values.resize(3, 5);
  table.values << 0, 1, 2, 3, 4, 0.1, 5, 6, 7, 8, 0.2, -1e-9, 1e9, 0.1 + 0.2, 1.0 / 3.0;
  const std::string path = temp_path("table.csv");
  sio::write_csv(path, table, {"written by a test", "two lines"});
  EXPECT_EQ(slurp(path).rfind("# written by a test\n# two lines\nt,p1_0", 0), 0u);
  const sio::Table back = sio::read_csv(path);
  EXPECT_EQ(back.header, table.header);
  EXPECT_EQ(back.values, table.values);
  const sio::Dataset d = sio::read_dataset(path, small_robot(), false);
  EXPECT_EQ(d.pressures(2, 2), 0.1 + 0.2);
  EXPECT_EQ(d.pressures(2, 3), 1.0 / 3.0);
  std::filesystem::remove(path);
}

TEST(IoCsv, WriteRejectsMismatchedShapes) {
  Eigen::VectorXd t(3);
  Eigen::MatrixXd q(2, 2);
  EXPECT_THROW(sio::write_trajectory_csv(temp_path("x.csv"), t, q, {"u1", "v1"}),
               std::invalid_argument);
  Eigen::MatrixXd q3(3, 2);
  EXPECT_THROW(sio::write_trajectory_csv(temp_path("x.csv"), t, q3, {"u1"}), std::invalid_argument);
  EXPECT_THROW(sio::write_trajectory_csv(temp_path("x.csv"), t, q3, {"u1", "v,1"}),
               std::invalid_argument);
}

// csv_table.hpp's fast path for plain decimals against std::from_chars, bit for bit: random
// doubles printed at 1-17 significant digits (fixed and %g), random digit strings with the
// point anywhere (leading zeros, trailing zeros, "5.", ".5", -0), and strings it must leave
// to from_chars (too many digits, mantissas above 2^53, exponents, junk). parse_number as a
// whole must agree with from_chars on every one of them.
TEST(IoCsv, PlainDecimalFastPathIsFromChars) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> exp10(-12, 12), ndig(1, 25), prec(1, 17), coin(0, 1);
  std::vector<std::string> cases = {"0",
                                    "-0",
                                    "5.",
                                    ".5",
                                    "-.5",
                                    "0.0",
                                    "9007199254740992",
                                    "9007199254740993",
                                    "0.1",
                                    "-0.153945",
                                    "53474.6",
                                    "1234567890123456789",
                                    "12345678901234567890",
                                    "1e5",
                                    "inf",
                                    "-",
                                    ".",
                                    "1.2.3",
                                    "--5",
                                    "0x10",
                                    "1e-400"};
  char buf[64];
  for (int i = 0; i < 200000; ++i) {
    const double v = mant(rng) * std::pow(10.0, exp10(rng));
    std::snprintf(buf, sizeof buf, coin(rng) ? "%.*f" : "%.*g", prec(rng), v);
    cases.emplace_back(buf);
    std::string digits;
    const int n = ndig(rng);
    for (int d = 0; d < n; ++d) digits += static_cast<char>('0' + rng() % 10);
    digits.insert(rng() % (digits.size() + 1), ".");
    if (coin(rng)) digits.insert(0, "-");
    cases.push_back(digits);
  }
  int fast = 0;
  for (const auto& c : cases) {
    const char* b = c.data();
    const char* e = b + c.size();
    double expected = 0.0;
    const auto r = std::from_chars(b, e, expected, std::chars_format::general);
    const bool whole = r.ec == std::errc() && r.ptr == e;
    double got = 0.0;
    if (softrne::io::detail::parse_plain_decimal(b, e, got)) {
      ++fast;
      ASSERT_TRUE(whole) << c;
      ASSERT_EQ(std::memcmp(&got, &expected, sizeof got), 0)
          << c << ": " << got << " vs " << expected;
    }
    double via_cell = 0.0;
    const auto status = softrne::io::detail::parse_number(c, via_cell);
    if (whole && std::isfinite(expected)) {
      ASSERT_EQ(status, softrne::io::detail::NumberStatus::Ok) << c;
      ASSERT_EQ(std::memcmp(&via_cell, &expected, sizeof via_cell), 0) << c;
    }
  }
  // Most printed doubles take the fast path (a test of a path never taken could not fail).
  EXPECT_GT(fast, static_cast<int>(cases.size() / 2));
  std::printf("[ info ] %d of %zu strings parsed by the fast path, all as from_chars\n", fast,
              cases.size());
}

TEST(IoCsv, HundredThousandRowsParseFast) {
  const sio::RobotSpec robot = sio::read_robot_json(std::string(kArmDir) + "/robot.json");
  std::string text =
      "# big\nt,p1_0,p1_1,p1_2,p1_3,p2_0,p2_1,p2_2,p2_3,p3_0,p3_1,p3_2,p3_3,u1,v1,u2,v2,u3,v3\n";
  const int N = 100000;
  text.reserve(static_cast<std::size_t>(N) * 130);
  char buf[64];
  for (int i = 0; i < N; ++i) {
    std::snprintf(buf, sizeof buf, "%.2f", 0.01 * i);
    text += buf;
    for (int k = 0; k < 12; ++k) {
      std::snprintf(buf, sizeof buf, ",%.1f", 1000.0 * k + 0.1 * (i % 1000));
      text += buf;
    }
    for (int k = 0; k < 6; ++k) {
      std::snprintf(buf, sizeof buf, ",%.6f", 1e-3 * ((i + k) % 500) - 0.25);
      text += buf;
    }
    text += '\n';
  }
  const auto start = std::chrono::steady_clock::now();
  const sio::Dataset d = sio::parse_dataset(text, "big.csv", robot, true);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(d.t.size(), N);
  EXPECT_EQ(d.angles.cols(), 6);
  EXPECT_DOUBLE_EQ(d.pressures(N - 1, 11), 11000.0 + 0.1 * ((N - 1) % 1000));
  RecordProperty("parse_seconds", std::to_string(seconds));
  std::printf("parsed %d rows x 19 columns (%.1f MB) in %.3f s\n", N,
              static_cast<double>(text.size()) / 1e6, seconds);
#ifdef NDEBUG
  EXPECT_LT(seconds, 1.0);
#endif
}

TEST(IoCsv, CorruptedFilesGiveInputErrorOnly) {
  const sio::RobotSpec robot = sio::read_robot_json(std::string(kArmDir) + "/robot.json");
  std::string original = slurp(std::string(kArmDir) + "/train.csv");
  original.resize(original.find('\n', 4000) + 1);  // the comments, the header and some rows
  std::mt19937 rng(54321);
  const std::string alphabet = ",.-+eE0123456789 \n\r#tpuv_naif\"\x01\xff";
  int accepted = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    std::string text = original;
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const std::size_t pos = rng() % text.size();
      switch (rng() % 3) {
        case 0:
          text[pos] = alphabet[rng() % alphabet.size()];
          break;
        case 1:
          text.erase(pos, 1 + rng() % 8);
          break;
        default:
          text.insert(pos, 1, alphabet[rng() % alphabet.size()]);
          break;
      }
    }
    try {
      const sio::Dataset d = sio::parse_dataset(text, "fuzz.csv", robot, iter % 2 == 0);
      ASSERT_EQ(d.pressures.rows(), d.t.size());
      ASSERT_EQ(d.pressures.cols(), 12);
      ++accepted;
    } catch (const sio::InputError& e) {
      ASSERT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      ASSERT_EQ(std::string(e.what()).rfind("fuzz.csv: ", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      FAIL() << "iteration " << iter << ": not an InputError: " << e.what();
    }
  }
  EXPECT_GT(accepted, 0);
}
