#pragma once
/// \file
/// \brief An arm's state equation x' = f(x, p) (paper eq. 23 with the effects) for any scalar
/// type, and its initial state; evaluates an ArmDescription (arm_description.hpp).

#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "softrne/config.hpp"
#include "softrne/algorithms/forward_dynamics.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/chain/dynamic_chain.hpp"

namespace softrne {
namespace detail {
/// True for segments with pressure inputs (an `actuation(p)` member: the CC joint).
template <class Seg, class = void>
struct has_actuation : std::false_type {};
template <class Seg>
struct has_actuation<Seg, std::void_t<decltype(std::declval<const Seg&>().actuation(
                              std::declval<Eigen::Matrix<typename Seg::Scalar, Eigen::Dynamic, 1>>()))>>
    : std::true_type {};
}  // namespace detail

/// \brief Evaluates the arm's state equation x' = f(x, p) for one scalar type: eq. 23 with the
/// effects. Holds its chain and workspace, so evaluation allocates nothing.
///
/// Arguments named xs are the effect states (x without q and qdot, size num_effect_states);
/// each effect sees its own slice of them.
template <class S>
class ArmDynamics {
 public:
  using VectorS = Eigen::Matrix<S, Eigen::Dynamic, 1>;  ///< a vector of the scalar type

  /// \brief The state equation of `desc`, which must outlive it.
  /// \param[in] desc The arm.
  explicit ArmDynamics(const ArmDescription& desc)
      : desc_(&desc), chain_(desc.make_chain<S>()), data_(chain_.make_data()) {
    // The payload link (if any) has no coordinates: nq of the chain equals desc.nq.
    p_eff_.resize(desc.num_inputs);
    tau_.resize(desc.nq);
  }

  /// \return The arm.
  const ArmDescription& description() const { return *desc_; }
  /// \return Its chain in scalar type S.
  const DynamicChain<S>& chain() const { return chain_; }
  /// \return The chain's workspace (what the last evaluation left).
  DynamicChainData<S>& data() { return data_; }

  /// \brief The pressures that drive the joints: the recorded ones changed by the effects.
  /// Effects that replace them (actuator_lag) act first, then those that transform them
  /// (chamber_gain), each group in list order; so the result does not depend on the order in
  /// which a fit added them.
  /// \param[in] xs The effect states.
  /// \param[in] p_recorded The recorded pressures, Pa.
  /// \param[out] p_eff The effective pressures, Pa.
  template <class X, class P>
  void effective_pressures(const X& xs, const P& p_recorded, VectorS& p_eff) const {
    const auto& d = *desc_;
    for (int i = 0; i < d.num_inputs; ++i) p_eff(i) = S(p_recorded(i));
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t k = 0; k < d.effects.size(); ++k)
        std::visit(
            [&](const auto& e) {
              if (std::decay_t<decltype(e)>::replaces_pressures == (pass == 0))
                e.template effective_pressures<S>(d.joints, own(xs, k), p_eff);
            },
            d.effects[k]);
  }

  /// \brief Generalised forces other than inertia and gravity: \f$K_{prs}p - Kq - K_d\dot q\f$
  /// plus the effects, at the effective pressures p and effect states xs (the u of
  /// forward_dynamics()).
  /// \param[in] q The coordinates, rad.
  /// \param[in] qd Their rates, rad/s.
  /// \param[in] p The effective pressures, Pa.
  /// \param[in] xs The effect states.
  /// \return The generalised forces (valid until the next call).
  /// The springs, dampers and pressure maps are the chain's segments' own (passive_force,
  /// actuation), built from the description's joints when this object was made.
  template <class Q, class Qd, class P, class X>
  const VectorS& joint_forces(const Q& q, const Qd& qd, const P& p, const X& xs) {
    const auto& d = *desc_;
    for (const auto& j : d.joints) {
      std::visit(
          [&](const auto& seg) {
            using Seg = std::decay_t<decltype(seg)>;
            constexpr int n = Seg::nq;
            if constexpr (n > 0) {
              auto t = tau_.template segment<n>(j.q_offset);
              t = seg.passive_force(q.template segment<n>(j.q_offset), qd.template segment<n>(j.q_offset));
              if constexpr (detail::has_actuation<Seg>::value)
                t += seg.actuation(p.segment(j.input_offset, seg.num_inputs()));
            }
          },
          chain_.segment(j.segment));
    }
    for (std::size_t k = 0; k < d.effects.size(); ++k)
      std::visit(
          [&](const auto& e) { e.template add_forces<S>(d.joints, q, qd, p, own(xs, k), tau_); },
          d.effects[k]);
    return tau_;
  }

  /// \brief Time derivative of the effect states (size num_effect_states) given the
  /// recorded pressures.
  /// \param[in] xs The effect states.
  /// \param[in] q The coordinates.
  /// \param[in] qd Their rates.
  /// \param[in] p_recorded The recorded pressures, Pa.
  /// \param[out] xsd Their time derivatives.
  template <class X, class Q, class Qd, class P, class Xd>
  void effect_state_derivative(const X& xs, const Q& q, const Qd& qd, const P& p_recorded,
                               Xd&& xsd) const {
    const auto& d = *desc_;
    for (std::size_t k = 0; k < d.effects.size(); ++k) {
      auto xsd_k = xsd.segment(d.effect_state_offsets[k], d.effect_state_size(k));
      std::visit(
          [&](const auto& e) {
            e.template state_derivative<S>(d.joints, own(xs, k), q, qd, p_recorded, xsd_k);
          },
          d.effects[k]);
    }
  }

  /// \brief x' = f(x, p_recorded): qdot, the accelerations of eq. 23 (forward dynamics with
  /// joint_forces()), and the effect states' derivatives.
  /// \param[in] x The state [q, qdot, effect states].
  /// \param[in] p_recorded The recorded pressures, Pa.
  /// \param[out] xdot Its time derivative.
  template <class X, class P, class Xd>
  void rhs(const X& x, const P& p_recorded, Xd& xdot) {
    const auto& d = *desc_;
    const int n = d.nq;
    const auto q = x.head(n);
    const auto qd = x.segment(n, n);
    const auto xs = x.segment(2 * n, d.num_effect_states);
    effective_pressures(xs, p_recorded, p_eff_);
    joint_forces(q, qd, p_eff_, xs);
    forward_dynamics(chain_, data_, q, qd, tau_);
    xdot.head(n) = qd;
    xdot.segment(n, n) = data_.qddot;
    effect_state_derivative(xs, q, qd, p_recorded, xdot.segment(2 * n, d.num_effect_states));
  }

 private:
  // Effect k's slice of the effect states.
  template <class X>
  auto own(const X& xs, std::size_t k) const {
    return xs.segment(desc_->effect_state_offsets[k], desc_->effect_state_size(k));
  }

  const ArmDescription* desc_;
  DynamicChain<S> chain_;
  DynamicChainData<S> data_;
  VectorS p_eff_, tau_;
};

/// \brief The state at rest at the coordinates q under the pressures p: [q, 0, the effects'
/// internal states at their at-rest values at q and p] (an actuator lag's pressures equal to p,
/// a Maxwell branch relaxed at q, ...). What initial_state() and static_equilibrium() start from.
/// \param[in] d The arm.
/// \param[in] q The coordinates (nq), not the measured angles.
/// \param[in] p The pressures, Pa.
/// \return The state (num_states).
SOFTRNE_SIM_INLINE Eigen::VectorXd rest_state(const ArmDescription& d, const Eigen::VectorXd& q, const Eigen::VectorXd& p)
#if SOFTRNE_SIM_BODIES
{
  Eigen::VectorXd x = Eigen::VectorXd::Zero(d.num_states());
  x.head(d.nq) = q;
  for (std::size_t k = 0; k < d.effects.size(); ++k) {
    auto xs = x.segment(2 * d.nq + d.effect_state_offsets[k], d.effect_state_size(k));
    std::visit([&](const auto& e) { e.initial_states(d.joints, q, p, xs); }, d.effects[k]);
  }
  return x;
}
#else
;
#endif

/// \brief Initial state: at the first measured configuration with the measurement model
/// inverted (q0 = (y0 - offset) ./ gain), at rest or at the measured rates (qdot0 = ydot0 ./
/// gain), effect states from q0 and the first recorded pressures (their at-rest values there,
/// rest_state(): a recording that starts in motion starts its effects' internal states as if
/// at rest). An empty y0 means q0 = 0; an empty ydot0, at rest.
/// \param[in] d The arm.
/// \param[in] q0_measured The first measured angles y0 (nq), or empty.
/// \param[in] p0 The first recorded pressures, Pa.
/// \param[in] qdot0_measured The measured angle rates at the first sample (nq), or empty.
/// \return The state [q0, qdot0, effect states].
SOFTRNE_SIM_INLINE Eigen::VectorXd initial_state(const ArmDescription& d, const Eigen::VectorXd& q0_measured,
                                                 const Eigen::VectorXd& p0,
                                                 const Eigen::VectorXd& qdot0_measured = Eigen::VectorXd())
#if SOFTRNE_SIM_BODIES
{
  Eigen::VectorXd x = rest_state(d,
                                 q0_measured.size() == d.nq ? d.coordinates_from_measured(q0_measured)
                                                            : Eigen::VectorXd(Eigen::VectorXd::Zero(d.nq)),
                                 p0);
  if (qdot0_measured.size() == d.nq) {
    Eigen::VectorXd gain, offset;
    d.measurement(gain, offset);
    x.segment(d.nq, d.nq) = qdot0_measured.cwiseQuotient(gain);
  }
  return x;
}
#else
;
#endif

}  // namespace softrne
