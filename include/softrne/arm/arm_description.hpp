#pragma once
/// \file
/// \brief An arm as the tools use it, its constant part: the joint table (springs, dampers and
/// pressure maps, paper eq. 23), the effects a fit added and the sizes; built from a robot
/// description (build_arm) and written back to one (to_robot_spec).
///
/// The arm layer sits between the chain (the Model/Data of the algorithms) and the simulator:
/// ArmDescription is what a fit changes, ArmDynamics (arm_dynamics.hpp) evaluates it.

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/chain/dynamic_chain.hpp"
#include "softrne/effects/effect_info.hpp"
#include "softrne/io/robot_spec.hpp"

namespace softrne {

/// \brief The constant description of an arm (double precision): joint table, effects, sizes.
/// The chain itself is built for any Scalar by `make_chain<S>()`.
struct ArmDescription {
  io::RobotSpec spec;  ///< what it was built from (segments, gravity)
  std::vector<ArmJoint> joints;  ///< the joints with coordinates, base to tip
  std::vector<AnyEffect> effects;  ///< the effects added to eq. 23, in order
  std::vector<std::string> coordinate_names;  ///< u1, v1, ..., in q's order
  std::vector<std::string> pressure_names;    ///< p1_0, ..., in the pressure vector's order
  int nq = 0;                 ///< number of coordinates
  int num_inputs = 0;         ///< number of pressure inputs
  int num_effect_states = 0;  ///< number of the effects' states
  std::vector<int> effect_state_offsets;  ///< effect k's first state among them

  /// Consistent (Euler-Lagrange of the lumped energy) or the paper's frozen-inertia eq. 18.
  InertiaRate inertia_rate = InertiaRate::Consistent;

  /// \brief State x = [q, qdot, effect states].
  /// \return Its size, 2 nq + num_effect_states.
  int num_states() const { return 2 * nq + num_effect_states; }

  /// \brief Index of the joint named `name`, or -1.
  /// \param[in] name A segment name.
  /// \return Its index in `joints`, or -1.
  int joint_index(const std::string& name) const {
    for (std::size_t i = 0; i < joints.size(); ++i)
      if (joints[i].name == name) return static_cast<int>(i);
    return -1;
  }

  /// \brief Size of effect k's slice of the effect states.
  /// \param[in] k An index into `effects`.
  /// \return Its number of states.
  int effect_state_size(std::size_t k) const {
    const int end = k + 1 < effect_state_offsets.size() ? effect_state_offsets[k + 1]
                                                         : num_effect_states;
    return end - effect_state_offsets[k];
  }

  /// Measurement model: the sensors report y = gain .* q + offset (sensor_gain,
  /// angle_offset); both nq vectors, gain 1 and offset 0 without effects.
  /// \param[out] gain The gains (nq).
  /// \param[out] offset The offsets (nq), rad.
  void measurement(Eigen::VectorXd& gain, Eigen::VectorXd& offset) const {
    gain = Eigen::VectorXd::Ones(nq);
    offset = Eigen::VectorXd::Zero(nq);
    for (const auto& e : effects)
      std::visit([&](const auto& x) { x.measurement(joints, gain, offset); }, e);
  }
  /// \return The measurement gains (nq); see measurement().
  Eigen::VectorXd measurement_gain() const {
    Eigen::VectorXd g, o;
    measurement(g, o);
    return g;
  }
  /// \return The measurement offsets (nq), rad; see measurement().
  Eigen::VectorXd measurement_offset() const {
    Eigen::VectorXd g, o;
    measurement(g, o);
    return o;
  }
  /// \brief What the sensors report for simulated coordinates q.
  /// \param[in] q Simulated coordinates (nq), rad.
  /// \return gain .* q + offset.
  Eigen::VectorXd measured(const Eigen::VectorXd& q) const {
    Eigen::VectorXd g, o;
    measurement(g, o);
    return g.cwiseProduct(q) + o;
  }
  /// \brief The simulated coordinates that the sensors report as y: (y - offset) ./ gain.
  /// \param[in] y Measured angles (nq), rad.
  /// \return The coordinates, rad.
  Eigen::VectorXd coordinates_from_measured(const Eigen::VectorXd& y) const {
    Eigen::VectorXd g, o;
    measurement(g, o);
    return (y - o).cwiseQuotient(g);
  }

  /// \brief Transport delay of the recorded pressures: the sum of the effects' delays.
  /// \return s.
  double input_delay() const {
    double d = 0;
    for (const auto& e : effects) d += std::visit([](const auto& x) { return x.input_delay(); }, e);
    return d;
  }

  /// \brief Mass of the segments of the spec, without effects.
  /// \return kg.
  double segment_mass() const {
    double m = 0;
    for (const auto& seg : spec.segments)
      std::visit([&](const auto& x) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(x)>, io::RevoluteJointSpec>) m += x.mass;
      }, seg);
    return m;
  }

  /// \brief Point mass the effects add at the tip (payload).
  /// \return kg.
  double tip_mass() const {
    double m = 0;
    for (const auto& e : effects) m += std::visit([](const auto& x) { return x.tip_mass(); }, e);
    return m;
  }

  /// \brief Factor on each segment's mass and inertia (mass_scale); 1 without effects.
  /// \return One factor per segment of the spec.
  std::vector<double> segment_mass_scale() const {
    std::vector<double> s(spec.segments.size(), 1.0);
    for (const auto& e : effects) std::visit([&](const auto& x) { x.mass_scale(joints, s); }, e);
    return s;
  }

  /// \brief The chain: the segments of the spec with their masses and inertias scaled by any
  /// mass_scale effect, plus a payload point mass if an effect adds one, and the springs,
  /// dampers and pressure maps of `joints` (the current, possibly fitted, values: the spec
  /// holds the declared ones).
  /// \tparam S The scalar type (double, or an AutoDiff type for the Jacobian).
  /// \return The runtime chain.
  template <class S>
  DynamicChain<S> make_chain() const {
    DynamicChain<S> c;
    const std::vector<double> scale = segment_mass_scale();
    std::vector<const ArmJoint*> joint_of(spec.segments.size(), nullptr);
    for (const auto& j : joints) joint_of[static_cast<std::size_t>(j.segment)] = &j;
    for (std::size_t s = 0; s < spec.segments.size(); ++s) {
      const auto& seg = spec.segments[s];
      if (const auto* cc = std::get_if<io::CCJointSpec>(&seg)) {
        const ArmJoint& jt = *joint_of[s];
        ConstantCurvatureJoint<S> j;
        // A CC joint's inertia follows from its mass and geometry (eqs. 19-22), so scaling
        // the mass scales the inertia too.
        j.mass = S(cc->mass * scale[s]);
        j.height = S(cc->height);
        j.diameter = S(cc->diameter);
        j.stiffness = jt.stiffness.cast<S>();
        j.damping = jt.damping.cast<S>();
        if (jt.pressure_to_torque.cols() > ConstantCurvatureJoint<S>::max_chambers)
          throw std::invalid_argument("joint '" + cc->name + "': more than 8 chambers");
        j.pressure_to_torque = jt.pressure_to_torque.cast<S>();
        if (cc->inertia_model == "distributed") {
          // The runtime chain has one distributed type, DistributedInertia<> (the default
          // number of points; build_arm rejects any other quadrature_points).
          c.add(j.template with_inertia<DistributedInertia<>>(), cc->name);
        } else {
          c.add(j, cc->name);
        }
      } else if (const auto* rl = std::get_if<io::RigidLinkSpec>(&seg)) {
        RigidLink<S> l;
        l.mass = S(rl->mass * scale[s]);
        l.length = S(rl->length);
        l.com = rl->com.cast<S>();
        l.inertia = (rl->inertia * scale[s]).cast<S>();
        c.add(l, rl->name);
      } else if (const auto* rj = std::get_if<io::RevoluteJointSpec>(&seg)) {
        const ArmJoint& jt = *joint_of[s];
        RevoluteJoint<S> r;
        r.axis = rj->axis.cast<S>();
        r.stiffness = S(jt.stiffness(0));
        r.damping = S(jt.damping(0));
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

/// \brief Names of an effect's parameters on this arm (effect_param_names with the
/// description's coordinate and pressure names).
/// \param[in] e An effect.
/// \param[in] d The arm.
/// \return One name per entry of e's params.
inline std::vector<std::string> effect_param_names(const AnyEffect& e, const ArmDescription& d) {
  return effect_param_names(e, d.joints, d.coordinate_names, d.pressure_names);
}

/// \brief Appends an effect to the description and gives it its slice of the effect states.
/// Throws std::invalid_argument if its parameter count does not match its scope and joints.
/// \param[in,out] d The arm.
/// \param[in] e The effect, with its joints, scope and params set.
/// \throws std::invalid_argument if e's params have the wrong size.
SOFTRNE_SIM_INLINE void add_effect(ArmDescription& d, AnyEffect e)
#if SOFTRNE_SIM_BODIES
{
  const int np = effect_num_params(e, d.joints);
  if (effect_base(e).params.size() != np)
    throw std::invalid_argument("effect '" + effect_name(e) + "': " +
                                std::to_string(effect_base(e).params.size()) +
                                " parameters given, its scope and joints need " +
                                std::to_string(np));
  d.effect_state_offsets.push_back(d.num_effect_states);
  d.num_effect_states += std::visit([&](const auto& x) { return x.num_states(d.joints); }, e);
  d.effects.push_back(std::move(e));
}
#else
;
#endif

/// \brief A candidate at its neutral values: effect `name` on `joints` (indices into the
/// joint table; all joints it applies to when empty) with `scope`. Throws
/// std::invalid_argument on an unknown name, a scope the effect does not allow, or a joint it
/// does not apply to.
/// \param[in] name The effect's name.
/// \param[in] d The arm.
/// \param[in] scope Its scope.
/// \param[in] joints Indices into d.joints; empty: every joint it applies to.
/// \return The effect, every parameter at its neutral value.
/// \throws std::invalid_argument as said above.
SOFTRNE_SIM_INLINE AnyEffect make_effect_at_neutral(const std::string& name, const ArmDescription& d,
                                                    Scope scope, std::vector<int> joints = {})
#if SOFTRNE_SIM_BODIES
{
  AnyEffect e;
  if (!make_effect(name, e))
    throw std::invalid_argument("effect '" + name + "': unknown effect name");
  if (!effect_scope_allowed(e, scope))
    throw std::invalid_argument("effect '" + name + "': scope '" + scope_name(scope) +
                                "' is not allowed");
  if (joints.empty()) {
    for (std::size_t j = 0; j < d.joints.size(); ++j)
      if (effect_applies_to(e, d.joints[j])) joints.push_back(static_cast<int>(j));
  } else {
    for (int j : joints)
      if (j < 0 || j >= static_cast<int>(d.joints.size()) ||
          !effect_applies_to(e, d.joints[static_cast<std::size_t>(j)]))
        throw std::invalid_argument("effect '" + name + "': does not apply to joint index " +
                                    std::to_string(j));
  }
  EffectBase& b = effect_base(e);
  b.joints = std::move(joints);
  b.scope = scope;
  const int np = effect_num_params(e, d.joints);
  b.params.resize(np);
  for (int k = 0; k < np; ++k) b.params(k) = effect_param_bounds(e, k, d.segment_mass()).neutral;
  return e;
}
#else
;
#endif

namespace detail {

/// \brief Reads an effect's parameters from a robot-file entry: the scope is the one whose
/// names (formats.md section 4) are exactly the keys present. `where` names the entry.
SOFTRNE_SIM_INLINE void read_effect_params(const io::EffectSpec& es, const ArmDescription& a,
                                           const std::string& where, AnyEffect& e)
#if SOFTRNE_SIM_BODIES
{
  EffectBase& b = effect_base(e);
  const int nk = effect_num_kinds(e);
  std::string kinds;
  for (int k = 0; k < nk; ++k) kinds += std::string(k ? ", " : "") + effect_param_info(e, k).name;
  if (es.params.empty())
    throw std::invalid_argument(where + ": field 'params': no parameters (kinds: " + kinds + ")");
  const std::vector<Scope> scopes = effect_scopes(e);
  std::vector<std::vector<std::string>> names(scopes.size());
  for (std::size_t s = 0; s < scopes.size(); ++s) {
    b.scope = scopes[s];
    names[s] = effect_param_names(e, a);
  }
  auto in = [](const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
  };
  // The scope whose names are exactly the keys; else the first that holds them all (and so
  // misses some).
  std::size_t pick = scopes.size();
  for (std::size_t s = 0; s < scopes.size(); ++s) {
    bool all = true;
    for (const auto& kv : es.params) all = all && in(names[s], kv.first);
    if (all && (pick == scopes.size() || names[s].size() == es.params.size())) pick = s;
    if (all && names[s].size() == es.params.size()) break;
  }
  if (pick < scopes.size()) {
    const std::size_t s = pick;
    b.scope = scopes[s];
    b.params.resize(static_cast<Eigen::Index>(names[s].size()));
    for (std::size_t k = 0; k < names[s].size(); ++k) {
      const auto it = es.params.find(names[s][k]);
      if (it == es.params.end())
        throw std::invalid_argument(where + ": field 'params': missing '" + names[s][k] + "' (" +
                                    scope_name(scopes[s]) + " scope)");
      b.params(static_cast<Eigen::Index>(k)) = it->second;
    }
    return;
  }
  // No scope holds them all: a key that fits none, or a mix.
  std::string forms;
  for (Scope sc : scopes)
    forms += std::string(forms.empty() ? "" : ", ") +
             (sc == Scope::Shared ? "'<kind>'" : std::string("'<kind>.<") + scope_name(sc) + ">'");
  std::string first_key;
  std::size_t first_scope = scopes.size();
  for (const auto& kv : es.params) {
    const std::string kind = kv.first.substr(0, kv.first.find('.'));
    bool known = false;
    for (int k = 0; k < nk; ++k) known = known || kind == effect_param_info(e, k).name;
    if (!known)
      throw std::invalid_argument(where + ": field 'params." + kv.first + "': unknown kind '" +
                                  kind + "' (kinds: " + kinds + ")");
    std::size_t s = 0;
    while (s < scopes.size() && !in(names[s], kv.first)) ++s;
    if (s == scopes.size())
      throw std::invalid_argument(where + ": field 'params." + kv.first +
                                  "': names no listed joint, coordinate or chamber (forms: " +
                                  forms + ")");
    if (first_scope == scopes.size()) {
      first_key = kv.first;
      first_scope = s;
    } else if (s != first_scope) {
      throw std::invalid_argument(where + ": field 'params': mixes scopes: '" + first_key + "' (" +
                                  scope_name(scopes[first_scope]) + ") and '" + kv.first + "' (" +
                                  scope_name(scopes[s]) + ")");
    }
  }
  throw std::invalid_argument(where + ": field 'params': inconsistent parameter names");
}
#else
;
#endif

}  // namespace detail

/// \brief Builds the description from a robot spec; its `effects` become model effects.
/// Throws std::invalid_argument naming the effect and field on an inconsistent effect.
///
/// The joint table carries each joint's K_spring, K_d and K_prs (eqs. 23-24).
/// \param[in] spec A robot, e.g. from io::read_robot_json().
/// \return The arm (chain constants, joint table, effects, sizes).
/// \throws std::invalid_argument naming the effect and field on an inconsistent effect.
SOFTRNE_SIM_INLINE ArmDescription build_arm(const io::RobotSpec& spec)
#if SOFTRNE_SIM_BODIES
{
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
  for (std::size_t i = 0; i < spec.effects.size(); ++i) {
    const io::EffectSpec& es = spec.effects[i];
    const std::string where = (spec.source.empty() ? std::string() : spec.source + ": ") +
                              "effects[" + std::to_string(i) + "] '" + es.name + "'";
    AnyEffect e;
    if (!make_effect(es.name, e))
      throw std::invalid_argument(where + ": field 'name': unknown effect name");
    EffectBase& b = effect_base(e);
    for (const auto& jn : es.joints) {
      const int ji = a.joint_index(jn);
      if (ji < 0)
        throw std::invalid_argument(where + ": field 'joints': '" + jn + "' is not a joint");
      if (!effect_applies_to(e, a.joints[static_cast<std::size_t>(ji)]))
        throw std::invalid_argument(where + ": field 'joints': the effect does not apply to '" +
                                    jn + "'");
      b.joints.push_back(ji);
    }
    detail::read_effect_params(es, a, where, e);
    add_effect(a, std::move(e));
  }
  return a;
}
#else
;
#endif

/// \brief The effects as robot-file entries (formats.md section 4), parameters by name.
/// \param[in] a The arm.
/// \return One entry per effect.
SOFTRNE_SIM_INLINE std::vector<io::EffectSpec> effect_specs(const ArmDescription& a)
#if SOFTRNE_SIM_BODIES
{
  std::vector<io::EffectSpec> out;
  for (const auto& e : a.effects) {
    io::EffectSpec s;
    s.name = effect_name(e);
    const EffectBase& b = effect_base(e);
    for (int j : b.joints) s.joints.push_back(a.joints[static_cast<std::size_t>(j)].name);
    const auto names = effect_param_names(e, a);
    for (std::size_t k = 0; k < names.size(); ++k) s.params[names[k]] = b.params(static_cast<Eigen::Index>(k));
    out.push_back(s);
  }
  return out;
}
#else
;
#endif

/// \brief The robot spec with the description's current stiffness, damping, pressure maps and
/// effects written back (what `softrne-fit` saves).
/// \param[in] a The arm.
/// \return Its robot spec.
SOFTRNE_SIM_INLINE io::RobotSpec to_robot_spec(const ArmDescription& a)
#if SOFTRNE_SIM_BODIES
{
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
#else
;
#endif

}  // namespace softrne
