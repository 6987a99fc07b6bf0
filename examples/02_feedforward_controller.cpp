// Controller use: feed-forward chamber pressures for a desired trajectory of a paper-like arm.
//
// Inverse dynamics of eq. 23 gives the torques the chambers must produce,
//   K_prs p = M(q) qdd + C(q, qd) qd + G(q) + K q + D qd,
// and for the four-chamber layout of eq. 24 (tau_u = dA (p0 - p1), tau_v = dA (p2 - p3)) the
// non-negative allocation with the least pressure puts |tau|/dA in one chamber of each pair
// and vents the other (plus an optional common bias for stiffness). The loop runs on a
// compile-time chain and a Data made once: nothing is allocated inside it (checked here).
#define EIGEN_RUNTIME_NO_MALLOC
#include <cmath>
#include <cstdio>

#include <softrne/softrne.hpp>

int main() {
  using S = double;
  using CC = softrne::ConstantCurvatureJoint<S>;
  using Link = softrne::RigidLink<S>;
  CC joint;
  joint.mass = 0.8;
  joint.height = 0.2;
  joint.diameter = 0.2;
  joint.stiffness << 30.0, 30.0;
  joint.damping << 2.0, 2.0;
  joint.pressure_to_torque = CC::four_chamber_map(0.06, 0.03);
  Link link;
  link.mass = 1.5;
  link.length = 0.15;
  link.com << 0, 0, 0.075;
  link.inertia = Eigen::Vector3d(0.0052, 0.0052, 0.0048).asDiagonal();
  Link tip = link;
  tip.mass = 0.4;
  tip.length = 0.05;
  tip.com << 0, 0, 0.025;
  tip.inertia = Eigen::Vector3d(0.00033, 0.00033, 0.0005).asDiagonal();
  softrne::Chain<CC, Link, CC, Link, CC, Link> arm(joint, link, joint, link, joint, tip);
  arm.gravity << 0, 0, 9.81;  // hanging, base z pointing down
  auto data = arm.make_data();

  using Vec = decltype(arm)::VectorQ;
  Vec q, qd, qdd, tau;
  const double bias = 5e3;  // Pa in both chambers of a pair: some co-contraction
  Eigen::Matrix<double, 12, 1> p;
  double p_max = 0;
  Eigen::internal::set_is_malloc_allowed(false);  // the control loop must not allocate
  for (int k = 0; k <= 200; ++k) {                // 2 s at 100 Hz
    const double t = 0.01 * k;
    for (int i = 0; i < 6; ++i) {  // a smooth desired trajectory per coordinate
      const double a = 0.3 + 0.1 * i, w = 2.0 + 0.5 * i;
      q(i) = a * std::sin(w * t);
      qd(i) = a * w * std::cos(w * t);
      qdd(i) = -a * w * w * std::sin(w * t);
    }
    tau = softrne::rnea(arm, data, q, qd, qdd);
    // + spring and damper of each joint (they oppose the motion; the chambers supply it).
    tau.segment<2>(0) -= std::get<0>(arm.segments).passive_force(q.segment<2>(0), qd.segment<2>(0));
    tau.segment<2>(2) -= std::get<2>(arm.segments).passive_force(q.segment<2>(2), qd.segment<2>(2));
    tau.segment<2>(4) -= std::get<4>(arm.segments).passive_force(q.segment<2>(4), qd.segment<2>(4));
    // Each joint's torques -> its four chambers (pressure_allocation.hpp).
    softrne::antagonistic_pressures(joint.pressure_to_torque, tau.segment<2>(0), bias, p.segment<4>(0));
    softrne::antagonistic_pressures(joint.pressure_to_torque, tau.segment<2>(2), bias, p.segment<4>(4));
    softrne::antagonistic_pressures(joint.pressure_to_torque, tau.segment<2>(4), bias, p.segment<4>(8));
    p_max = std::max(p_max, p.maxCoeff());
    if (k % 50 == 0) {
      Eigen::internal::set_is_malloc_allowed(true);  // printing is outside the control law
      std::printf(
          "t = %.2f s  tau = [% .3f % .3f % .3f % .3f % .3f % .3f] N m  p1 = [%.0f %.0f %.0f %.0f] "
          "Pa\n",
          t, tau(0), tau(1), tau(2), tau(3), tau(4), tau(5), p(0), p(1), p(2), p(3));
      Eigen::internal::set_is_malloc_allowed(false);
    }
  }
  Eigen::internal::set_is_malloc_allowed(true);
  std::printf("largest chamber pressure along the trajectory: %.0f kPa\n", p_max / 1e3);
  return 0;
}
