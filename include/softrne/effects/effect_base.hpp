#pragma once
/// \file
/// \brief The interface every effect implements: a named term added to the declared model
/// (paper eq. 23) that the closed loop can discover in data (formats.md section 4). Each
/// effect's header describes it completely (name, parameter kinds with bounds, allowed
/// scopes, the joints it applies to); effect_info.hpp reads those descriptions generically,
/// so no other file keeps effect-specific lists.

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace softrne {

/// \brief How many values a parameter kind has: one for the whole effect, one per listed
/// joint, per coordinate of each listed joint, or per chamber of each listed joint.
enum class Scope { Shared, PerJoint, PerCoordinate, PerChamber };

/// \brief "shared", "joint", "coordinate", "chamber" (used in messages and reports).
/// \param[in] s A scope.
/// \return Its name in robot files and reports.
inline const char* scope_name(Scope s) {
  switch (s) {
    case Scope::Shared: return "shared";
    case Scope::PerJoint: return "joint";
    case Scope::PerCoordinate: return "coordinate";
    case Scope::PerChamber: return "chamber";
  }
  return "?";
}

/// \brief One parameter kind of an effect: its name in robot files, the physically plausible
/// range a fit searches, whether the fit works on its logarithm, the value at which the
/// effect does nothing, and its unit.
///
/// `per_arm_mass`: when true, `lower` and `upper` are per kg of the arm's declared segment
/// mass (effect_param_bounds multiplies them by it); a payload's plausible range scales with
/// the arm that carries it. `neutral` is never scaled.
struct ParamInfo {
  const char* name;  ///< name in robot files and reports (e.g. "T")
  double lower, upper;
  /// \var lower
  /// \brief Smallest plausible value (per kg of arm mass if per_arm_mass).
  /// \var upper
  /// \brief Largest plausible value (per kg of arm mass if per_arm_mass).
  bool log_scale;  ///< the fit searches log(value)
  double neutral;  ///< the value at which the effect does nothing
  const char* unit;  ///< SI unit, for reports
  bool per_arm_mass = false;  ///< lower and upper scale with the arm's mass
};

/// \brief What an effect knows of one joint with coordinates (a CC joint or a revolute joint).
struct ArmJoint {
  std::string name;      ///< the segment's name in the robot file
  int segment = 0;       ///< index in the chain
  int q_offset = 0;      ///< first coordinate
  int nq = 0;            ///< 2 (CC) or 1 (revolute)
  int input_offset = 0;  ///< first pressure column
  int num_inputs = 0;    ///< chambers (0 for a revolute joint)
  Eigen::Vector2d stiffness = Eigen::Vector2d::Zero();  ///< first nq entries used
  Eigen::Vector2d damping = Eigen::Vector2d::Zero();  ///< first nq entries used
  Eigen::Matrix<double, 2, Eigen::Dynamic> pressure_to_torque;  ///< 2 x num_inputs (CC)

  /// \return True for a CC joint (two coordinates), false for a revolute joint.
  bool is_cc() const { return nq == 2; }
};

/// \brief Common data and the no-op hooks. An effect type derives from Effect<itself> and
/// redefines the hooks it needs; the model calls them through std::visit, so there is no
/// virtual call.
///
/// Parameter layout: `params` holds "units" in order (Shared: one; PerJoint: one per listed
/// joint; PerCoordinate: one per coordinate of each listed joint, joint by joint;
/// PerChamber: one per chamber of each listed joint), and within a unit the effect's
/// parameter kinds contiguously: `params(unit * num_kinds + kind)`.
struct EffectBase {
  std::vector<int> joints;  ///< indices into the arm's joint table
  Scope scope = Scope::Shared;  ///< how many values each parameter kind has
  Eigen::VectorXd params;       ///< the values, in the layout above

  /// \brief Number of units (see the layout above) on the arm's joint table.
  /// \param[in] arm The arm's joint table.
  /// \return 1 (Shared), one per listed joint, per coordinate or per chamber of them.
  int num_units(const std::vector<ArmJoint>& arm) const {
    switch (scope) {
      case Scope::Shared: return 1;
      case Scope::PerJoint: return static_cast<int>(joints.size());
      case Scope::PerCoordinate:
      case Scope::PerChamber: {
        int n = 0;
        for (int j : joints) n += units_of(arm[static_cast<std::size_t>(j)]);
        return n;
      }
    }
    return 0;
  }

  /// \brief Unit of the i-th listed joint; `sub` is the coordinate (PerCoordinate) or chamber
  /// (PerChamber) within the joint, ignored otherwise. O(i): effects visit few joints.
  /// \param[in] arm The arm's joint table.
  /// \param[in] i Index into `joints`.
  /// \param[in] sub Coordinate or chamber within the joint.
  /// \return The unit's index in the layout.
  int unit(const std::vector<ArmJoint>& arm, std::size_t i, int sub = 0) const {
    switch (scope) {
      case Scope::Shared: return 0;
      case Scope::PerJoint: return static_cast<int>(i);
      case Scope::PerCoordinate:
      case Scope::PerChamber: {
        int u = 0;
        for (std::size_t l = 0; l < i; ++l) u += units_of(arm[static_cast<std::size_t>(joints[l])]);
        return u + sub;
      }
    }
    return 0;
  }

  /// \brief Parameter `kind` of the unit of listed joint i (see unit()), for an effect with
  /// `num_kinds` kinds. Effect<E>::value supplies num_kinds.
  /// \param[in] arm The arm's joint table.
  /// \param[in] i Index into `joints`.
  /// \param[in] kind Index of the parameter kind.
  /// \param[in] sub Coordinate or chamber within the joint.
  /// \param[in] num_kinds The effect's number of parameter kinds.
  /// \return The parameter's value.
  double value_of(const std::vector<ArmJoint>& arm, std::size_t i, int kind, int sub,
                  int num_kinds) const {
    return params(static_cast<Eigen::Index>(unit(arm, i, sub)) * num_kinds + kind);
  }

  // --- hooks (no-ops) -------------------------------------------------------------------
  // xs is the effect's own slice of the effect states; q, qd the coordinates and rates;
  // p the pressures (effective ones in add_forces, recorded ones in state_derivative).

  /// \brief Extra states of the effect (e.g. the lagged pressures).
  /// \return How many (0 here).
  int num_states(const std::vector<ArmJoint>&) const { return 0; }
  /// True for effects whose effective_pressures replace p (actuator_lag): ArmDynamics applies
  /// them before the ones that transform p (chamber_gain), so the list order does not matter.
  static constexpr bool replaces_pressures = false;
  /// Changes the pressures that drive the joints (and every other effect).
  template <class S, class X, class P>
  void effective_pressures(const std::vector<ArmJoint>&, const X&, P&) const {}
  /// Generalised forces added to tau = K_prs p - K q - D qdot.
  template <class S, class Q, class Qd, class P, class X, class Tau>
  void add_forces(const std::vector<ArmJoint>&, const Q&, const Qd&, const P&, const X&,
                  Tau&) const {}
  /// Time derivative of the effect's states.
  template <class S, class X, class Q, class Qd, class P, class Xd>
  void state_derivative(const std::vector<ArmJoint>&, const X&, const Q&, const Qd&, const P&,
                        Xd&) const {}
  /// Initial states given the simulated coordinates and recorded pressures at the first
  /// sample.
  template <class Q, class P, class X>
  void initial_states(const std::vector<ArmJoint>&, const Q&, const P&, X&) const {}
  /// Measurement model: the sensors report y = gain .* q + offset; an effect multiplies
  /// `gain` and adds to `offset` (both of size nq).
  void measurement(const std::vector<ArmJoint>&, Eigen::VectorXd&, Eigen::VectorXd&) const {}
  /// \brief Point mass added at the tip of the chain.
  /// \return kg (0 here).
  double tip_mass() const { return 0; }
  /// Multiplies the masses and inertias of the chain's segments (one factor per segment).
  void mass_scale(const std::vector<ArmJoint>&, std::vector<double>&) const {}
  /// \brief Transport delay of the recorded pressures.
  /// \return s (0 here).
  double input_delay() const { return 0; }

 private:
  int units_of(const ArmJoint& j) const {
    return scope == Scope::PerCoordinate ? j.nq : j.num_inputs;
  }
};

/// \brief The base of effect type E: EffectBase plus value() with E's number of kinds.
template <class E>
struct Effect : EffectBase {
  /// Parameter `kind` (index into E::param_info) of listed joint i; `sub` = coordinate or
  /// chamber within the joint for PerCoordinate / PerChamber scopes.
  /// \param[in] arm The arm's joint table.
  /// \param[in] i Index into `joints`.
  /// \param[in] kind Index into E::param_info.
  /// \param[in] sub Coordinate or chamber within the joint.
  /// \return The parameter's value.
  double value(const std::vector<ArmJoint>& arm, std::size_t i, int kind = 0,
               int sub = 0) const {
    return value_of(arm, i, kind, sub, static_cast<int>(E::param_info.size()));
  }
};

}  // namespace softrne
