// errors.hpp must compile on its own: it is included first.
#include <string>

#include <gtest/gtest.h>

#include "softrne/io/errors.hpp"

namespace sio = softrne::io;

TEST(IoErrors, MessageIsFileWhereWhat) {
  const sio::InputError e(sio::Category::OutOfRange, "robot.json",
                          "segments[2] 'joint2': field 'mass'", "must be > 0 (got -1)");
  EXPECT_STREQ(e.what(), "robot.json: segments[2] 'joint2': field 'mass': must be > 0 (got -1)");
  EXPECT_EQ(e.category(), sio::Category::OutOfRange);
  EXPECT_EQ(e.source(), "robot.json");
  EXPECT_EQ(e.where(), "segments[2] 'joint2': field 'mass'");
  EXPECT_EQ(e.detail(), "must be > 0 (got -1)");
}

TEST(IoErrors, NoWhere) {
  const sio::InputError e(sio::Category::Empty, "a.csv", "", "empty file");
  EXPECT_STREQ(e.what(), "a.csv: empty file");
}

TEST(IoErrors, MessageIsAlwaysOneLine) {
  const sio::InputError e(sio::Category::BadNumber, "a\nb.csv", "line 3",
                          std::string("not a number: 'x\r\n\ty") + '\0' + "'");
  const std::string m = e.what();
  EXPECT_EQ(m.find('\n'), std::string::npos);
  EXPECT_EQ(m.find('\r'), std::string::npos);
  EXPECT_NE(m.find("a\\nb.csv"), std::string::npos);
}

TEST(IoErrors, QuotedTruncates) {
  EXPECT_EQ(sio::detail::quoted("abc"), "'abc'");
  EXPECT_EQ(sio::detail::quoted(std::string(100, 'x'), 5), "'xxxxx...'");
}

TEST(IoErrors, FormatDoubleRoundTrips) {
  EXPECT_EQ(sio::detail::format_double(-1.0), "-1");
  EXPECT_EQ(sio::detail::format_double(0.1), "0.1");
  EXPECT_EQ(std::stod(sio::detail::format_double(0.1 + 0.2)), 0.1 + 0.2);
}

TEST(IoErrors, CategoryNames) {
  EXPECT_STREQ(sio::to_string(sio::Category::MissingField), "MissingField");
  EXPECT_STREQ(sio::to_string(sio::Category::LineTooLong), "LineTooLong");
}

TEST(IoErrors, ReadMissingFile) {
  try {
    sio::detail::read_text_file("/nonexistent/softrne/robot.json");
    FAIL() << "no exception";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::FileNotFound);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/softrne/robot.json: cannot open file"),
              std::string::npos);
  }
}

TEST(IoErrors, ReadDirectoryFails) {
  try {
    sio::detail::read_text_file("/");
    FAIL() << "no exception";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::ReadFailed) << e.what();
  }
}

TEST(IoErrors, WriteIntoMissingDirectoryFails) {
  try {
    sio::detail::write_text_file("/nonexistent/softrne/out.csv", "x");
    FAIL() << "no exception";
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::WriteFailed) << e.what();
  }
}
