// Included first: the header must compile on its own.
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include <softrne/fit/parameters.hpp>

using softrne::fit::Parameter;
using softrne::fit::ParameterSet;

TEST(FitParameters, RoundTripLinearAndLog) {
  ParameterSet ps({{"k", 2.0, -1.0, 3.0, false}, {"E", 1e5, 1e3, 1e7, true}});
  ASSERT_EQ(ps.size(), 2);
  const Eigen::VectorXd x = ps.initial();
  const Eigen::VectorXd u = ps.to_normalised(x);
  EXPECT_DOUBLE_EQ(u[0], 0.75);
  EXPECT_NEAR(u[1], 0.5, 1e-15);  // geometric midpoint of [1e3, 1e7]
  const Eigen::VectorXd back = ps.to_physical(u);
  EXPECT_NEAR(back[0], 2.0, 1e-15);
  EXPECT_NEAR(back[1], 1e5, 1e-9);
  // The box ends map exactly onto the bounds.
  EXPECT_EQ(ps.to_physical(1, 0.0), 1e3);
  EXPECT_EQ(ps.to_physical(1, 1.0), 1e7);
  // Out-of-box values are clamped, never extrapolated.
  EXPECT_EQ(ps.to_physical(0, 1.5), 3.0);
  EXPECT_EQ(ps.to_normalised(0, -7.0), 0.0);
  // Chain-rule factor dx/du.
  EXPECT_DOUBLE_EQ(ps.dphysical_dnormalised(0, 2.0), 4.0);
  EXPECT_NEAR(ps.dphysical_dnormalised(1, 1e5), 1e5 * std::log(1e4), 1e-6);
  EXPECT_EQ(ps.index_of("E"), 1);
  EXPECT_EQ(ps.index_of("nope"), -1);
}

TEST(FitParameters, Validation) {
  ParameterSet ps;
  EXPECT_THROW(ps.add({"a", 1.0, 2.0, 2.0, false}), std::invalid_argument);  // lower == upper
  EXPECT_THROW(ps.add({"a", 1.0, 3.0, 2.0, false}), std::invalid_argument);  // lower > upper
  EXPECT_THROW(ps.add({"a", 1.0, 0.0, 2.0, true}), std::invalid_argument);   // log with lower 0
  EXPECT_THROW(ps.add({"a", NAN, 0.0, 2.0, false}), std::invalid_argument);  // non-finite
  EXPECT_THROW(ps.add({"", 1.0, 0.0, 2.0, false}), std::invalid_argument);   // no name
  EXPECT_EQ(ps.add({"a", 1.0, 0.0, 2.0, false}), 0);
  EXPECT_THROW(ps.add({"a", 1.0, 0.0, 2.0, false}), std::invalid_argument);  // duplicate
  EXPECT_TRUE(ps.notes().empty());
  // Initial value outside the bounds: clamped, with a note.
  EXPECT_EQ(ps.add({"b", 5.0, 0.0, 2.0, false}), 1);
  EXPECT_EQ(ps[1].initial, 2.0);
  ASSERT_EQ(ps.notes().size(), 1u);
  EXPECT_NE(ps.notes()[0].find("clamped"), std::string::npos);
}
