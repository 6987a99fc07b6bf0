// softrne against Pinocchio, an independent implementation (spatial algebra, CRBA, ABA), on
// chains of revolute joints and rigid links: random axes, off-axis centres of mass, full
// inertia tensors, several rigid links in a row, revolute joints without a link between,
// links before the first joint. Built only when Pinocchio's C++ package is found.
#include <algorithm>
#include <cstdio>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <random>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "softrne/softrne.hpp"

namespace {

namespace pin = pinocchio;
using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using Link = softrne::RigidLink<double>;
using Rev = softrne::RevoluteJoint<double>;

/// A random physical inertia about the centre of mass: Q diag(a, b, c) Q^T with the principal
/// moments satisfying the triangle inequality.
Matrix3d random_inertia(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(0.3, 1.0);
  const double a = u(rng), b = u(rng);
  std::uniform_real_distribution<double> uc(std::abs(a - b) + 0.05, a + b - 0.05);
  const double c = uc(rng);
  const Matrix3d Q = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
  return scale * Q * Vector3d(a, b, c).asDiagonal() * Q.transpose();
}

Vector3d random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vector3d(n(rng), n(rng), n(rng)).normalized();
}

Link random_link(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Link l;
  l.mass = 0.5 + 1.5 * std::abs(u(rng));
  l.length = std::abs(u(rng)) < 0.15 ? 0.0 : 0.3 * std::abs(u(rng));
  l.com = Vector3d(0.05 * u(rng), 0.05 * u(rng), 0.15 * u(rng));
  l.inertia = random_inertia(rng, 0.02 * l.mass);
  return l;
}

/// `layout`: 'R' revolute joint, 'L' rigid link, base to tip. Axes are random unless
/// `aligned` (then x, y or z, as RX/RY/RZ joints in Pinocchio).
softrne::DynamicChain<double> make_chain(const std::string& layout, bool aligned,
                                         std::mt19937& rng) {
  softrne::DynamicChain<double> c;
  int j = 0;
  for (char s : layout) {
    if (s == 'R') {
      Rev r;
      r.axis = aligned ? Vector3d::Unit(j % 3) : random_unit(rng);
      ++j;
      c.add(r);
    } else {
      c.add(random_link(rng));
    }
  }
  c.gravity = 9.81 * random_unit(rng);
  return c;
}

/// The same chain in Pinocchio: joint i sits where the links since joint i-1 have carried the
/// frame; a link's body is attached to the last joint (or the universe) at that placement.
pin::Model to_pinocchio(const softrne::DynamicChain<double>& c) {
  pin::Model m;
  pin::JointIndex parent = 0;
  pin::SE3 placement = pin::SE3::Identity();
  for (int i = 0; i < c.num_segments(); ++i) {
    if (const auto* r = std::get_if<Rev>(&c.segment(i))) {
      const std::string name = "j" + std::to_string(i);
      if (r->axis == Vector3d::UnitX())
        parent = m.addJoint(parent, pin::JointModelRX(), placement, name);
      else if (r->axis == Vector3d::UnitY())
        parent = m.addJoint(parent, pin::JointModelRY(), placement, name);
      else if (r->axis == Vector3d::UnitZ())
        parent = m.addJoint(parent, pin::JointModelRZ(), placement, name);
      else
        parent = m.addJoint(parent, pin::JointModelRevoluteUnaligned(r->axis), placement, name);
      placement = pin::SE3::Identity();
    } else {
      const Link& l = std::get<Link>(c.segment(i));
      m.appendBodyToJoint(parent, pin::Inertia(l.mass, l.com, l.inertia), placement);
      placement = placement * pin::SE3(Matrix3d::Identity(), Vector3d(0, 0, l.length));
    }
  }
  m.gravity.linear(c.gravity);
  return m;
}

double rel(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

TEST(Pinocchio, RevoluteAndRigidChainsAgree) {
  std::mt19937 rng(2024);
  const std::string layouts[] = {"RL",     "RLRLRLRLRLRL", "LRRLLRLRRRL",
                                 "RRLRRL", "LLRLLLRLRLL",  "RLRRLRLLRLRRLRLRLLRLRRLRLRLRLRL"};
  double worst[5] = {0, 0, 0, 0, 0};
  int cases = 0;
  for (const std::string& layout : layouts) {
    for (bool aligned : {false, true}) {
      for (int rep = 0; rep < 5; ++rep) {
        const auto chain = make_chain(layout, aligned, rng);
        auto data = chain.make_data();
        const pin::Model model = to_pinocchio(chain);
        pin::Data pd(model);
        const int nq = chain.num_coordinates();
        ASSERT_EQ(model.nq, nq);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        for (int s = 0; s < 10; ++s) {
          const VectorXd q = VectorXd::NullaryExpr(nq, [&] { return 3.0 * u(rng); });
          const VectorXd qd = VectorXd::NullaryExpr(nq, [&] { return 2.0 * u(rng); });
          const VectorXd qdd = VectorXd::NullaryExpr(nq, [&] { return 5.0 * u(rng); });
          const VectorXd tau = VectorXd::NullaryExpr(nq, [&] { return 10.0 * u(rng); });
          const double e[5] = {
              rel(softrne::rnea(chain, data, q, qd, qdd), pin::rnea(model, pd, q, qd, qdd)),
              [&] {
                const MatrixXd M = softrne::mass_matrix(chain, data, q);
                pin::crba(model, pd, q, pin::Convention::LOCAL);
                pd.M.triangularView<Eigen::StrictlyLower>() =
                    pd.M.transpose().triangularView<Eigen::StrictlyLower>();
                return rel(M, pd.M);
              }(),
              rel(softrne::gravity(chain, data, q), pin::computeGeneralizedGravity(model, pd, q)),
              rel(softrne::bias(chain, data, q, qd, true), pin::nonLinearEffects(model, pd, q, qd)),
              rel(softrne::forward_dynamics(chain, data, q, qd, tau),
                  pin::aba(model, pd, q, qd, tau, pin::Convention::LOCAL))};
          for (int k = 0; k < 5; ++k) {
            EXPECT_LT(e[k], 1e-10) << "quantity " << k << ", layout " << layout;
            worst[k] = std::max(worst[k], e[k]);
          }
          ++cases;
        }
      }
    }
  }
  std::printf(
      "[ info ] %d states; worst relative difference to Pinocchio: rnea %.1e, "
      "M/crba %.1e, gravity %.1e, bias/nle %.1e, forward dynamics/aba %.1e\n",
      cases, worst[0], worst[1], worst[2], worst[3], worst[4]);
}

}  // namespace
