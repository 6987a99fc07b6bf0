#pragma once
/// \file
/// \brief The interface every effect implements: a named term added to the declared model
/// (paper eq. 23) that the closed loop can discover in data (formats.md section 4).

#include <string>
#include <vector>

#include <Eigen/Core>

namespace softrne {

/// \brief What an effect knows of one joint with coordinates (a CC joint or a revolute joint).
struct ArmJoint {
  std::string name;
  int segment = 0;       ///< index in the chain
  int q_offset = 0;      ///< first coordinate
  int nq = 0;            ///< 2 (CC) or 1 (revolute)
  int input_offset = 0;  ///< first pressure column
  int num_inputs = 0;    ///< chambers (0 for a revolute joint)
  Eigen::Vector2d stiffness = Eigen::Vector2d::Zero();  ///< first nq entries used
  Eigen::Vector2d damping = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, Eigen::Dynamic> pressure_to_torque;  ///< 2 x num_inputs (CC)
  bool is_cc() const { return nq == 2; }
};

/// \brief Common data and the no-op hooks. An effect type derives from it and redefines the
/// hooks it needs; the model calls them through std::visit, so there is no virtual call.
///
/// Parameters: either one value shared by all listed joints, or one value (or, for
/// per-coordinate effects, one per coordinate) per joint, in `params` in that order.
struct EffectBase {
  std::vector<int> joints;  ///< indices into the arm's joint table
  bool shared = true;
  Eigen::VectorXd params;

  /// Number of parameters a joint uses (1 for most effects).
  static constexpr int params_per_joint = 1;

  /// Parameter k of the i-th listed joint.
  double param(std::size_t i, int k = 0, int per_joint = 1) const {
    return shared ? params(k) : params(static_cast<Eigen::Index>(i) * per_joint + k);
  }

  // --- hooks (no-ops) -------------------------------------------------------------------
  /// Extra states of the effect (e.g. the lagged pressures).
  int num_states(const std::vector<ArmJoint>&) const { return 0; }
  /// Generalised forces added to tau = K_prs p - K q - D qdot.
  template <class S, class Q, class P, class Tau>
  void add_forces(const std::vector<ArmJoint>&, const Q&, const Q&, const P&, Tau&) const {}
  /// Replaces the pressures that drive the joints by the effect's states.
  template <class S, class X, class P>
  void effective_pressures(const std::vector<ArmJoint>&, const X&, P&) const {}
  /// Time derivative of the effect's states given the recorded pressures.
  template <class S, class X, class P, class Xd>
  void state_derivative(const std::vector<ArmJoint>&, const X&, const P&, Xd&) const {}
  /// Initial states given the recorded pressures at the first sample.
  template <class X, class P>
  void initial_states(const std::vector<ArmJoint>&, const P&, X&) const {}
  /// Added to the simulated coordinates to give what the sensors report.
  void measurement_offset(const std::vector<ArmJoint>&, Eigen::VectorXd&) const {}
  /// Point mass added at the tip of the chain (kg).
  double tip_mass() const { return 0; }
};

}  // namespace softrne
