// robot_spec.hpp and robot_validate.hpp must compile on their own: included first.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "softrne/io/robot_spec.hpp"
#include "softrne/io/robot_validate.hpp"

namespace sio = softrne::io;

namespace {

sio::RobotSpec mixed_robot() {
  sio::RobotSpec r;
  r.name = "mixed";
  r.gravity = Eigen::Vector3d(0, 0, -9.81);
  r.source = "code";
  r.segments.push_back(sio::make_cc_joint("j1", 0.8, 0.2, 0.2, 0.06, 0.03, {40, 40}, {3, 3}));
  sio::RigidLinkSpec link;
  link.name = "link1";
  link.mass = 1.5;
  link.length = 0.15;
  link.com = Eigen::Vector3d(0, 0, 0.075);
  link.inertia = sio::inertia_from_array(0.0052, 0.0052, 0.0048, 0, 0, 0);
  r.segments.push_back(link);
  sio::RevoluteJointSpec wrist;
  wrist.name = "wrist";
  wrist.axis = Eigen::Vector3d::UnitZ();
  r.segments.push_back(wrist);
  sio::CCJointSpec j2 = sio::make_cc_joint("j2", 0.5, 0.1, 0.1, 0.03, 0.01, {10, 10}, {1, 1});
  j2.pressure_to_torque.resize(2, 3);
  j2.pressure_to_torque << 1, -0.5, -0.5, 0, 0.8, -0.8;
  j2.custom_pressure_map = true;
  r.segments.push_back(j2);
  return r;
}

}  // namespace

TEST(IoRobotSpec, DefaultPressureMapIsEq24) {
  const auto P = sio::default_pressure_to_torque(0.06, 0.03);
  const double pi = 3.14159265358979323846;
  const double dA = 0.06 * pi * 0.03 * 0.03;
  ASSERT_EQ(P.rows(), 2);
  ASSERT_EQ(P.cols(), 4);
  EXPECT_DOUBLE_EQ(P(0, 0), dA);
  EXPECT_DOUBLE_EQ(P(0, 1), -dA);
  EXPECT_EQ(P(0, 2), 0.0);
  EXPECT_EQ(P(0, 3), 0.0);
  EXPECT_EQ(P(1, 0), 0.0);
  EXPECT_EQ(P(1, 1), 0.0);
  EXPECT_DOUBLE_EQ(P(1, 2), dA);
  EXPECT_DOUBLE_EQ(P(1, 3), -dA);
}

TEST(IoRobotSpec, NamesInChainOrder) {
  const auto r = mixed_robot();
  EXPECT_EQ(sio::num_cc_joints(r), 2u);
  EXPECT_EQ(sio::num_coordinates(r), 5u);
  EXPECT_EQ(sio::num_pressure_columns(r), 7u);
  EXPECT_EQ(sio::coordinate_names(r), (std::vector<std::string>{"u1", "v1", "qwrist", "u2", "v2"}));
  EXPECT_EQ(sio::pressure_column_names(r),
            (std::vector<std::string>{"p1_0", "p1_1", "p1_2", "p1_3", "p2_0", "p2_1", "p2_2"}));
  EXPECT_STREQ(sio::segment_type(r.segments[1]), "rigid_link");
  EXPECT_EQ(sio::segment_name(r.segments[2]), "wrist");
  EXPECT_EQ(sio::segment_nq(r.segments[2]), 1);
}

TEST(IoRobotSpec, InertiaArrayRoundTrip) {
  const auto I = sio::inertia_from_array(1, 2, 3, 0.1, 0.2, 0.3);
  EXPECT_EQ(I, I.transpose());
  EXPECT_EQ(I(0, 1), 0.1);
  EXPECT_EQ(I(0, 2), 0.2);
  EXPECT_EQ(I(1, 2), 0.3);
  const auto a = sio::inertia_to_array(I);
  EXPECT_EQ(sio::inertia_from_array(a[0], a[1], a[2], a[3], a[4], a[5]), I);
}

TEST(IoRobotSpec, ValidateAcceptsGoodRobot) {
  EXPECT_NO_THROW(sio::validate_robot(mixed_robot()));
}

TEST(IoRobotSpec, ValidateRejectsBadValuesBuiltInCode) {
  auto r = mixed_robot();
  std::get<sio::CCJointSpec>(r.segments[3]).stiffness[1] = -2.0;
  try {
    sio::validate_robot(r);
    FAIL();
  } catch (const sio::InputError& e) {
    EXPECT_EQ(e.category(), sio::Category::OutOfRange);
    EXPECT_STREQ(e.what(), "code: segments[3] 'j2': field 'stiffness[1]': must be >= 0 (got -2)");
  }
  r = mixed_robot();
  std::get<sio::CCJointSpec>(r.segments[0]).pressure_to_torque.resize(2, 0);
  EXPECT_THROW(sio::validate_robot(r), sio::InputError);
  r = mixed_robot();
  std::get<sio::RigidLinkSpec>(r.segments[1]).inertia(0, 1) = 0.001;  // not symmetric
  EXPECT_THROW(sio::validate_robot(r), sio::InputError);
  r = mixed_robot();
  r.gravity[2] = std::nan("");
  EXPECT_THROW(sio::validate_robot(r), sio::InputError);
  r = mixed_robot();
  r.effects.push_back({"payload", {"nosuch"}, {}, ""});
  EXPECT_THROW(sio::validate_robot(r), sio::InputError);
}
