#pragma once
/// \file
/// \brief A whole arm as the tools use it: the chain, the joints' springs, dampers and pressure
/// maps (paper eq. 23), and the effects a fit added; built from a robot description.

#include <stdexcept>
#include <type_traits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "softrne/algorithms/forward_dynamics.hpp"
#include "softrne/chain/dynamic_chain.hpp"
#include "softrne/effects/effect_list.hpp"
#include "softrne/io/robot_spec.hpp"

namespace softrne {

/// \brief The constant description of an arm (double precision): joint table, effects, sizes.
/// The chain itself is built for any Scalar by `make_chain<S>()`.
struct ArmDescription {
  io::RobotSpec spec;  ///< what it was built from (segments, gravity)
  std::vector<ArmJoint> joints;
  std::vector<AnyEffect> effects;
  std::vector<std::string> coordinate_names;
  std::vector<std::string> pressure_names;
  int nq = 0;
  int num_inputs = 0;
  int num_effect_states = 0;
  std::vector<int> effect_state_offsets;
  /// Consistent (Euler-Lagrange of the lumped energy) or the paper's frozen-inertia eq. 18.
  InertiaRate inertia_rate = InertiaRate::Consistent;

  /// State x = [q, qdot, effect states].
  int num_states() const { return 2 * nq + num_effect_states; }

  /// Index of the joint named `name`, or -1.
  int joint_index(const std::string& name) const {
    for (std::size_t i = 0; i < joints.size(); ++i)
      if (joints[i].name == name) return static_cast<int>(i);
    return -1;
  }

  /// Offsets added to simulated coordinates to give measured angles (angle_offset).
  Eigen::VectorXd measurement_offset() const {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(nq);
    for (const auto& e : effects)
      std::visit([&](const auto& x) { x.measurement_offset(joints, y); }, e);
    return y;
  }

  /// Mass of the segments of the spec (kg), without effects.
  double segment_mass() const {
    double m = 0;
    for (const auto& seg : spec.segments)
      std::visit([&](const auto& x) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(x)>, io::RevoluteJointSpec>) m += x.mass;
      }, seg);
    return m;
  }

  double tip_mass() const {
    double m = 0;
    for (const auto& e : effects) m += std::visit([](const auto& x) { return x.tip_mass(); }, e);
    return m;
  }

  /// \brief The chain (segments of the spec, plus a payload point mass if an effect adds one).
  template <class S>
  DynamicChain<S> make_chain() const {
    DynamicChain<S> c;
    for (const auto& seg : spec.segments) {
      if (const auto* cc = std::get_if<io::CCJointSpec>(&seg)) {
        ConstantCurvatureJoint<S> j;
        j.mass = S(cc->mass);
        j.height = S(cc->height);
        j.diameter = S(cc->diameter);
        j.stiffness = cc->stiffness.cast<S>();
        j.damping = cc->damping.cast<S>();
        if (cc->pressure_to_torque.cols() > ConstantCurvatureJoint<S>::max_chambers)
          throw std::invalid_argument("joint '" + cc->name + "': more than 8 chambers");
        j.pressure_to_torque = cc->pressure_to_torque.cast<S>();
        if (cc->inertia_model == "distributed") {
          // The runtime chain has one distributed type, DistributedInertia<> (the default
          // number of points; build_arm rejects any other quadrature_points).
          c.add(j.template with_inertia<DistributedInertia<>>(), cc->name);
        } else {
          c.add(j, cc->name);
        }
      } else if (const auto* rl = std::get_if<io::RigidLinkSpec>(&seg)) {
        RigidLink<S> l;
        l.mass = S(rl->mass);
        l.length = S(rl->length);
        l.com = rl->com.cast<S>();
        l.inertia = rl->inertia.cast<S>();
        c.add(l, rl->name);
      } else if (const auto* rj = std::get_if<io::RevoluteJointSpec>(&seg)) {
        RevoluteJoint<S> r;
        r.axis = rj->axis.cast<S>();
        r.stiffness = S(rj->stiffness);
        r.damping = S(rj->damping);
        c.add(r, rj->name);
      }
    }
    const double m_tip = tip_mass();
    if (m_tip != 0.0) {
      RigidLink<S> p;
      p.mass = S(m_tip);
      c.add(p, "payload");
    }
    c.gravity = spec.gravity.cast<S>();
    c.inertia_rate = inertia_rate;
    return c;
  }
};

/// \brief Number of parameters of an effect on these joints.
inline int effect_num_params(const AnyEffect& e, const std::vector<ArmJoint>& joints) {
  const EffectBase& b = effect_base(e);
  if (std::holds_alternative<AngleOffset>(e)) {
    int n = 0;
    for (int j : b.joints) n += joints[static_cast<std::size_t>(j)].nq;
    return n;
  }
  if (std::holds_alternative<Payload>(e) || b.shared) return 1;
  return static_cast<int>(b.joints.size());
}

/// \brief Names of an effect's parameters, in the order of its `params`: `beta` when shared,
/// `beta.joint2` per joint, `offset.u1`-style per coordinate for angle_offset.
inline std::vector<std::string> effect_param_names(const AnyEffect& e,
                                                   const std::vector<ArmJoint>& joints,
                                                   const std::vector<std::string>& coordinate_names) {
  const EffectBase& b = effect_base(e);
  const std::string base =
      std::visit([](const auto& x) { return std::string(std::decay_t<decltype(x)>::param_name); }, e);
  std::vector<std::string> names;
  if (std::holds_alternative<AngleOffset>(e)) {
    for (int j : b.joints) {
      const ArmJoint& jt = joints[static_cast<std::size_t>(j)];
      for (int k = 0; k < jt.nq; ++k)
        names.push_back(base + "." + coordinate_names[static_cast<std::size_t>(jt.q_offset + k)]);
    }
  } else if (std::holds_alternative<Payload>(e) || b.shared) {
    names.push_back(base);
  } else {
    for (int j : b.joints) names.push_back(base + "." + joints[static_cast<std::size_t>(j)].name);
  }
  return names;
}

/// \brief Builds the description from a robot spec; its `effects` become model effects.
/// Throws std::invalid_argument naming the effect and field on an inconsistent effect.
inline ArmDescription build_arm(const io::RobotSpec& spec) {
  ArmDescription a;
  a.spec = spec;
  a.spec.effects.clear();
  int q = 0, p = 0, cc_index = 0;
  for (std::size_t s = 0; s < spec.segments.size(); ++s) {
    const auto& seg = spec.segments[s];
    if (const auto* cc = std::get_if<io::CCJointSpec>(&seg)) {
      ++cc_index;
      // "inertia_model": "distributed" runs with DistributedInertia<> (kDefaultGaussPoints).
      if (cc->inertia_model == "distributed" && cc->quadrature_points != 0 &&
          cc->quadrature_points != kDefaultGaussPoints)
        throw std::invalid_argument(
            (spec.source.empty() ? std::string() : spec.source + ": ") + "segments[" +
            std::to_string(s) + "] '" + cc->name + "': field 'quadrature_points': the runtime " +
            "chain supports 0 (default) or " + std::to_string(kDefaultGaussPoints) + " (got " +
            std::to_string(cc->quadrature_points) + ")");
      ArmJoint j;
      j.name = cc->name;
      j.segment = static_cast<int>(s);
      j.q_offset = q;
      j.nq = 2;
      j.input_offset = p;
      j.num_inputs = static_cast<int>(cc->pressure_to_torque.cols());
      j.stiffness = cc->stiffness;
      j.damping = cc->damping;
      j.pressure_to_torque = cc->pressure_to_torque;
      a.joints.push_back(j);
      a.coordinate_names.push_back("u" + std::to_string(cc_index));
      a.coordinate_names.push_back("v" + std::to_string(cc_index));
      for (int k = 0; k < j.num_inputs; ++k)
        a.pressure_names.push_back("p" + std::to_string(cc_index) + "_" + std::to_string(k));
      q += 2;
      p += j.num_inputs;
    } else if (const auto* rj = std::get_if<io::RevoluteJointSpec>(&seg)) {
      ArmJoint j;
      j.name = rj->name;
      j.segment = static_cast<int>(s);
      j.q_offset = q;
      j.nq = 1;
      j.input_offset = p;
      j.stiffness(0) = rj->stiffness;
      j.damping(0) = rj->damping;
      j.pressure_to_torque.resize(2, 0);
      a.joints.push_back(j);
      a.coordinate_names.push_back("q" + rj->name);
      q += 1;
    }
  }
  a.nq = q;
  a.num_inputs = p;
  for (const auto& es : spec.effects) {
    AnyEffect e;
    if (!make_effect(es.name, e))
      throw std::invalid_argument("effect '" + es.name + "': unknown effect name");
    EffectBase& b = effect_base(e);
    for (const auto& jn : es.joints) {
      const int ji = a.joint_index(jn);
      if (ji < 0) throw std::invalid_argument("effect '" + es.name + "': field 'joints': '" + jn + "' is not a joint");
      b.joints.push_back(ji);
    }
    // Shared when the file uses the bare parameter name ("beta"), per joint otherwise
    // ("beta.joint1"); angle_offset is always per coordinate, payload always shared.
    const std::string bare =
        std::visit([](const auto& x) { return std::string(std::decay_t<decltype(x)>::param_name); }, e);
    b.shared = !std::holds_alternative<AngleOffset>(e) &&
               (std::holds_alternative<Payload>(e) || es.params.count(bare) > 0);
    const auto names = effect_param_names(e, a.joints, a.coordinate_names);
    b.params.resize(static_cast<Eigen::Index>(names.size()));
    for (std::size_t k = 0; k < names.size(); ++k) {
      const auto it = es.params.find(names[k]);
      if (it == es.params.end())
        throw std::invalid_argument("effect '" + es.name + "': field 'params': missing '" + names[k] + "'");
      b.params(static_cast<Eigen::Index>(k)) = it->second;
    }
    a.effects.push_back(e);
  }
  int offset = 0;
  for (const auto& e : a.effects) {
    a.effect_state_offsets.push_back(offset);
    offset += std::visit([&](const auto& x) { return x.num_states(a.joints); }, e);
  }
  a.num_effect_states = offset;
  return a;
}

/// \brief The effects as robot-file entries (formats.md section 4), parameters by name.
inline std::vector<io::EffectSpec> effect_specs(const ArmDescription& a) {
  std::vector<io::EffectSpec> out;
  for (const auto& e : a.effects) {
    io::EffectSpec s;
    s.name = effect_name(e);
    const EffectBase& b = effect_base(e);
    for (int j : b.joints) s.joints.push_back(a.joints[static_cast<std::size_t>(j)].name);
    const auto names = effect_param_names(e, a.joints, a.coordinate_names);
    for (std::size_t k = 0; k < names.size(); ++k) s.params[names[k]] = b.params(static_cast<Eigen::Index>(k));
    out.push_back(s);
  }
  return out;
}

/// \brief The robot spec with the description's current stiffness, damping, pressure maps and
/// effects written back (what `softrne-fit` saves).
inline io::RobotSpec to_robot_spec(const ArmDescription& a) {
  io::RobotSpec s = a.spec;
  for (const auto& j : a.joints) {
    auto& seg = s.segments[static_cast<std::size_t>(j.segment)];
    if (auto* cc = std::get_if<io::CCJointSpec>(&seg)) {
      cc->stiffness = j.stiffness;
      cc->damping = j.damping;
      cc->pressure_to_torque = j.pressure_to_torque;
    } else if (auto* rj = std::get_if<io::RevoluteJointSpec>(&seg)) {
      rj->stiffness = j.stiffness(0);
      rj->damping = j.damping(0);
    }
  }
  s.effects = effect_specs(a);
  return s;
}

/// \brief Evaluates the arm's state equation x' = f(x, p) for one scalar type: eq. 23 with the
/// effects. Holds its chain and workspace, so evaluation allocates nothing.
template <class S>
class ArmDynamics {
 public:
  using VectorS = Eigen::Matrix<S, Eigen::Dynamic, 1>;

  explicit ArmDynamics(const ArmDescription& desc)
      : desc_(&desc), chain_(desc.make_chain<S>()), data_(chain_.make_data()) {
    // The payload link (if any) has no coordinates: nq of the chain equals desc.nq.
    p_eff_.resize(desc.num_inputs);
    tau_.resize(desc.nq);
  }

  const ArmDescription& description() const { return *desc_; }
  const DynamicChain<S>& chain() const { return chain_; }
  DynamicChainData<S>& data() { return data_; }

  /// \brief Generalised forces other than inertia and gravity: \f$K_{prs}p - Kq - K_d\dot q\f$
  /// plus the effects, at the effective pressures p.
  template <class Q, class P>
  const VectorS& joint_forces(const Q& q, const Q& qd, const P& p) {
    const auto& d = *desc_;
    for (const auto& j : d.joints) {
      for (int k = 0; k < j.nq; ++k) {
        S t = -(S(j.stiffness(k)) * q(j.q_offset + k) + S(j.damping(k)) * qd(j.q_offset + k));
        for (int c = 0; c < j.num_inputs; ++c)
          t += S(j.pressure_to_torque(k, c)) * p(j.input_offset + c);
        tau_(j.q_offset + k) = t;
      }
    }
    for (const auto& e : d.effects)
      std::visit([&](const auto& x) { x.template add_forces<S>(d.joints, q, qd, p, tau_); }, e);
    return tau_;
  }

  /// \brief x' = f(x, p_recorded).
  template <class X, class P, class Xd>
  void rhs(const X& x, const P& p_recorded, Xd& xdot) {
    const auto& d = *desc_;
    const int n = d.nq;
    const auto q = x.head(n);
    const auto qd = x.segment(n, n);
    for (int i = 0; i < d.num_inputs; ++i) p_eff_(i) = S(p_recorded(i));
    for (std::size_t k = 0; k < d.effects.size(); ++k) {
      const auto xs = x.segment(2 * n + d.effect_state_offsets[k], d.num_effect_states - d.effect_state_offsets[k]);
      std::visit([&](const auto& e) { e.template effective_pressures<S>(d.joints, xs, p_eff_); }, d.effects[k]);
    }
    joint_forces(q, qd, p_eff_);
    forward_dynamics(chain_, data_, q, qd, tau_);
    xdot.head(n) = qd;
    xdot.segment(n, n) = data_.qddot;
    for (std::size_t k = 0; k < d.effects.size(); ++k) {
      const int off = d.effect_state_offsets[k];
      const int len = d.num_effect_states - off;
      const auto xs = x.segment(2 * n + off, len);
      auto xds = xdot.segment(2 * n + off, len);
      std::visit([&](const auto& e) { e.template state_derivative<S>(d.joints, xs, p_recorded, xds); },
                 d.effects[k]);
    }
  }

 private:
  const ArmDescription* desc_;
  DynamicChain<S> chain_;
  DynamicChainData<S> data_;
  VectorS p_eff_, tau_;
};

/// \brief Initial state: at rest at the first measured configuration (less angle offsets),
/// effect states from the first recorded pressures.
inline Eigen::VectorXd initial_state(const ArmDescription& d, const Eigen::VectorXd& q0_measured,
                                     const Eigen::VectorXd& p0) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.num_states());
  if (q0_measured.size() == d.nq) x.head(d.nq) = q0_measured - d.measurement_offset();
  for (std::size_t k = 0; k < d.effects.size(); ++k) {
    const int off = d.effect_state_offsets[k];
    auto xs = x.segment(2 * d.nq + off, d.num_effect_states - off);
    std::visit([&](const auto& e) { e.initial_states(d.joints, p0, xs); }, d.effects[k]);
  }
  return x;
}

}  // namespace softrne
