// The per-joint "inertia_model" option of robot.json down to the runtime chain: "distributed"
// builds ConstantCurvatureJoint<double, DistributedInertia<>>, the default stays lumped, a bad
// value is a one-line error naming file, segment and field.
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <unsupported/Eigen/AutoDiff>

#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/io/robot_json.hpp"

namespace sio = softrne::io;
using nlohmann::json;

namespace io_test_robot_json_inertia_model {

const char* const kArmA = SOFTRNE_DATA_DIR "/arm-a-1/robot.json";

json arm_a() {
  std::ifstream f(kArmA);
  return json::parse(f);
}

// Index in "segments" of the k-th cc joint.
std::size_t cc_segment(const json& j, int k) {
  int seen = 0;
  for (std::size_t i = 0; i < j["segments"].size(); ++i)
    if (j["segments"][i]["type"] == "cc_joint" && seen++ == k) return i;
  throw std::logic_error("no such joint");
}

TEST(RobotJsonInertiaModel, DistributedLoadsAndBuildsTheDistributedSegment) {
  json j = arm_a();
  const std::size_t s3 = cc_segment(j, 2);
  j["segments"][s3]["inertia_model"] = "distributed";
  const sio::RobotSpec spec = sio::parse_robot_json(j.dump(), "robot.json");
  EXPECT_EQ(std::get<sio::CCJointSpec>(spec.segments[s3]).inertia_model, "distributed");
  EXPECT_EQ(std::get<sio::CCJointSpec>(spec.segments[0]).inertia_model, "lumped");
  const softrne::ArmDescription arm = softrne::build_arm(spec);
  const auto chain = arm.make_chain<double>();
  EXPECT_TRUE(std::holds_alternative<softrne::DistributedCCJoint<double>>(
      chain.segment(static_cast<int>(s3))));
  EXPECT_TRUE(std::holds_alternative<softrne::ConstantCurvatureJoint<double>>(chain.segment(0)));
  // Written back unchanged (what softrne-fit saves).
  const sio::RobotSpec back = sio::parse_robot_json(sio::to_json(softrne::to_robot_spec(arm)).dump(), "x");
  EXPECT_EQ(std::get<sio::CCJointSpec>(back.segments[s3]).inertia_model, "distributed");
  // The distributed joint changes M (last joint's diagonal: lumped is larger).
  const sio::RobotSpec lumped = sio::parse_robot_json(arm_a().dump(), "robot.json");
  const auto chain_l = softrne::build_arm(lumped).make_chain<double>();
  auto dd = chain.make_data();
  auto dl = chain_l.make_data();
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(chain.num_coordinates(), 0.3);
  const Eigen::MatrixXd Md = softrne::mass_matrix(chain, dd, q);
  const Eigen::MatrixXd Ml = softrne::mass_matrix(chain_l, dl, q);
  const int n = chain.num_coordinates();
  EXPECT_GT(Ml(n - 1, n - 1), 1.1 * Md(n - 1, n - 1));
  // Cast to another scalar keeps the model (the simulator's AutoDiff Jacobian).
  const auto chain_ad = arm.make_chain<Eigen::AutoDiffScalar<Eigen::VectorXd>>();
  EXPECT_TRUE(std::holds_alternative<softrne::DistributedCCJoint<Eigen::AutoDiffScalar<Eigen::VectorXd>>>(
      chain_ad.segment(static_cast<int>(s3))));
}

TEST(RobotJsonInertiaModel, BadValueIsOneLineErrorNamingFileSegmentField) {
  json j = arm_a();
  j["segments"][cc_segment(j, 1)]["inertia_model"] = "Distributed";
  try {
    sio::parse_robot_json(j.dump(), "robot.json");
    FAIL() << "accepted a bad inertia_model";
  } catch (const sio::InputError& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
    EXPECT_NE(w.find("robot.json"), std::string::npos) << w;
    EXPECT_NE(w.find("'joint2'"), std::string::npos) << w;
    EXPECT_NE(w.find("'inertia_model'"), std::string::npos) << w;
    EXPECT_NE(w.find("\"lumped\" or \"distributed\""), std::string::npos) << w;
  }
}

TEST(RobotJsonInertiaModel, QuadraturePointsOtherThanTheRuntimeDefaultAreRejected) {
  json j = arm_a();
  const std::size_t s1 = cc_segment(j, 0);
  j["segments"][s1]["inertia_model"] = "distributed";
  j["segments"][s1]["quadrature_points"] = softrne::kDefaultGaussPoints;
  EXPECT_NO_THROW(softrne::build_arm(sio::parse_robot_json(j.dump(), "robot.json")));
  j["segments"][s1]["quadrature_points"] = softrne::kDefaultGaussPoints + 3;
  try {
    softrne::build_arm(sio::parse_robot_json(j.dump(), "robot.json"));
    FAIL() << "accepted quadrature_points";
  } catch (const std::invalid_argument& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
    EXPECT_NE(w.find("robot.json: segments[0] 'joint1': field 'quadrature_points'"), std::string::npos) << w;
  }
}

// Numbers for docs/model.md: lumped vs distributed M over arm-a-1's workspace (|u|, |v| <=
// 0.7 rad, what its data sets reach), as it is and with links 10x lighter.
TEST(RobotJsonInertiaModel, ArmA1LumpedVsDistributedMassMatrix) {
  for (double link_scale : {1.0, 0.1}) {
    json jl = arm_a();
    for (auto& s : jl["segments"])
      if (s["type"] == "rigid_link") {
        s["mass"] = s["mass"].get<double>() * link_scale;
        for (auto& x : s["inertia"]) x = x.get<double>() * link_scale;
      }
    json jd = jl;
    for (auto& s : jd["segments"])
      if (s["type"] == "cc_joint") s["inertia_model"] = "distributed";
    const auto cl = softrne::build_arm(sio::parse_robot_json(jl.dump(), "l")).make_chain<double>();
    const auto cd = softrne::build_arm(sio::parse_robot_json(jd.dump(), "d")).make_chain<double>();
    auto dl = cl.make_data();
    auto dd = cd.make_data();
    const int n = cl.num_coordinates();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(-0.7, 0.7);
    const int samples = 2000;
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(n), lo = Eigen::VectorXd::Constant(n, 1e300),
                    hi = Eigen::VectorXd::Constant(n, -1e300);
    double full_mean = 0, full_max = 0;
    for (int k = 0; k < samples; ++k) {
      Eigen::VectorXd q(n);
      for (int i = 0; i < n; ++i) q(i) = U(rng);
      const Eigen::MatrixXd Ml = softrne::mass_matrix(cl, dl, q);
      const Eigen::MatrixXd Md = softrne::mass_matrix(cd, dd, q);
      for (int i = 0; i < n; ++i) {
        const double r = Ml(i, i) / Md(i, i) - 1;
        mean(i) += r / samples;
        lo(i) = std::min(lo(i), r);
        hi(i) = std::max(hi(i), r);
      }
      const double f = (Ml - Md).norm() / Md.norm();
      full_mean += f / samples;
      full_max = std::max(full_max, f);
    }
    std::printf("[ info ] arm-a-1, links x%.1f: (M_lumped,ii / M_distributed,ii - 1) over %d random q, "
                "|u|,|v| <= 0.7\n", link_scale, samples);
    for (int i = 0; i < n; ++i)
      std::printf("[ info ]   q%d: mean %+.2f %%, min %+.2f %%, max %+.2f %%\n", i + 1, 100 * mean(i),
                  100 * lo(i), 100 * hi(i));
    std::printf("[ info ]   |M_l - M_d|_F / |M_d|_F: mean %.2f %%, max %.2f %%\n", 100 * full_mean,
                100 * full_max);
    EXPECT_GT(lo(n - 1), 0.0);  // the lumped model overestimates the last joint's inertia
  }
}

}  // namespace io_test_robot_json_inertia_model
