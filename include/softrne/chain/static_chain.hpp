#pragma once
/// \file
/// \brief Compile-time chain of heterogeneous segments.

#include <array>
#include <tuple>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "softrne/chain/articulated_workspace.hpp"
#include "softrne/chain/derivative_workspace.hpp"
#include "softrne/chain/motion.hpp"
#include "softrne/config.hpp"
#include "softrne/segments/segment_concept.hpp"

namespace softrne {

template <class Chain>
struct ChainData;

/// \brief A serial chain whose segment types are known at compile time, base to tip.
///
/// The number of coordinates `nq` is a compile-time constant, so q, qdot, M are fixed-size
/// and evaluation never allocates. The chain is the Model (constant description); all scratch
/// lives in `Data` (made once with `make_data()`), so evaluation is reentrant.
template <class... Segments>
class Chain {
  static_assert(sizeof...(Segments) > 0, "softrne::Chain needs at least one segment");

 public:
  /// The segments' common scalar type (double, long double, an AutoDiff type).
  using Scalar = typename std::tuple_element_t<0, std::tuple<Segments...>>::Scalar;
  static_assert((std::is_same_v<Scalar, typename Segments::Scalar> && ...),
                "softrne::Chain: all segments must use the same Scalar type");
  static constexpr int num_segments = static_cast<int>(sizeof...(Segments));  ///< base to tip
  static constexpr int nq = (0 + ... + Segments::nq);  ///< number of coordinates
  using VectorQ = Eigen::Matrix<Scalar, nq, 1>;        ///< q, qdot, qddot, tau (fixed size)
  using MatrixQ = Eigen::Matrix<Scalar, nq, nq>;       ///< M (fixed size)
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;         ///< a 3-vector of the scalar type
  using Data = ChainData<Chain>;                       ///< the workspace type (make_data())

  std::tuple<Segments...> segments;  ///< the segments, base to tip (constants only)

  /// Gravitational acceleration \f$g^0\f$ in the base frame (eq. 16); for a hanging arm
  /// (base z down) set it to (0, 0, 9.81).
  Vector3 gravity = Vector3(Scalar(0), Scalar(0), Scalar(-9.81));
  /// Whether the CC joints' inertia rate enters (Consistent, default) or not (PaperFrozen,
  /// the paper's eq. 18).
  InertiaRate inertia_rate = InertiaRate::Consistent;

  /// \brief Default-constructed segments.
  Chain() { (check_segment<Segments>(), ...); }
  /// \brief The chain of these segments, base to tip.
  /// \param[in] segs One segment per type, in order.
  explicit Chain(Segments... segs) : segments(std::move(segs)...) {
    (check_segment<Segments>(), ...);
  }

  /// \return nq, the size of q, qdot, qddot and tau.
  int num_coordinates() const { return nq; }
  /// \return A workspace for this chain (one per thread); the algorithms allocate nothing.
  Data make_data() const { return Data(*this); }

  /// \brief A fixed-size argument of another size does not compile (detail::check_argument);
  /// a dynamic-size one (a VectorXd passed to a fixed chain) is checked in debug builds, as
  /// Eigen checks sizes. The hot path of a controller pays nothing.
  /// \param[in] size The argument's size (the algorithm's and the argument's names are
  ///   unused here; DynamicChain::check_argument puts them in its message).
  void check_argument(const char*, const char*, Eigen::Index size) const {
    SOFTRNE_ASSERT(size == nq, "softrne::Chain: an argument's size is not the chain's nq");
    (void)size;
  }
  /// \brief Nothing to check: the Data type belongs to this chain type alone.
  void check_data(const Data&) const {}

  /// \brief Offset of segment I's coordinates in q.
  /// \tparam I A segment index.
  /// \return The index of segment I's first coordinate.
  template <std::size_t I>
  static constexpr int q_offset() {
    constexpr int sizes[] = {Segments::nq...};
    int o = 0;
    for (std::size_t k = 0; k < I; ++k) o += sizes[k];
    return o;
  }

  /// \brief Calls f(segment, kinematics, index, q_offset) base to tip.
  /// \param[in,out] data The workspace whose per-segment kinematics f receives.
  /// \param[in] f A generic callable (each segment with its own type; no virtual call).
  template <class DataT, class F>
  void forward(DataT& data, F&& f) const {
    forward_impl(data, f, std::index_sequence_for<Segments...>{});
  }
  /// \brief Calls f(segment, kinematics, index, q_offset) tip to base.
  /// \param[in,out] data The workspace whose per-segment kinematics f receives.
  /// \param[in] f A generic callable (each segment with its own type; no virtual call).
  template <class DataT, class F>
  void backward(DataT& data, F&& f) const {
    backward_impl(data, f, std::index_sequence_for<Segments...>{});
  }

  /// \brief Calls f(segment, kinematics, index, q_offset) for segment i alone.
  /// \param[in,out] data The workspace whose segment-i kinematics f receives.
  /// \param[in] i The segment's index, 0 <= i < num_segments.
  /// \param[in] f A generic callable, as for forward().
  template <class DataT, class F>
  void visit_segment(DataT& data, int i, F&& f) const {
    visit_one(data, i, f, std::index_sequence_for<Segments...>{});
  }

  /// \brief The same chain in another scalar type (e.g. an AutoDiff scalar for derivatives).
  /// \tparam NewScalar The new scalar type.
  /// \return A Chain of the converted segments.
  template <class NewScalar>
  auto cast() const {
    return cast_impl<NewScalar>(std::index_sequence_for<Segments...>{});
  }

 private:
  template <std::size_t I, class DataT, class F>
  void visit(DataT& data, F& f) const {
    f(std::get<I>(segments), std::get<I>(data.kinematics), static_cast<int>(I), q_offset<I>());
  }
  template <class DataT, class F, std::size_t... I>
  void forward_impl(DataT& data, F& f, std::index_sequence<I...>) const {
    (visit<I>(data, f), ...);
  }
  template <class DataT, class F, std::size_t... I>
  void backward_impl(DataT& data, F& f, std::index_sequence<I...>) const {
    (visit<sizeof...(Segments) - 1 - I>(data, f), ...);
  }
  template <class DataT, class F, std::size_t... I>
  void visit_one(DataT& data, int i, F& f, std::index_sequence<I...>) const {
    ((static_cast<int>(I) == i ? visit<I>(data, f) : void()), ...);
  }
  template <class NewScalar, std::size_t... I>
  auto cast_impl(std::index_sequence<I...>) const {
    Chain<decltype(std::get<I>(segments).template cast<NewScalar>())...> c(
        std::get<I>(segments).template cast<NewScalar>()...);
    c.gravity = gravity.template cast<NewScalar>();
    c.inertia_rate = inertia_rate;
    return c;
  }
};

/// \brief Per-evaluation workspace of a compile-time chain: everything the algorithms write.
template <class... Segments>
struct ChainData<Chain<Segments...>> {
  using ChainT = Chain<Segments...>;        ///< the chain this workspace serves
  using Scalar = typename ChainT::Scalar;   ///< its scalar type
  static constexpr int N = ChainT::num_segments;  ///< its number of segments

  /// Per segment: what compute_kinematics() computed (rotations, Jacobians, inertias).
  std::tuple<typename Segments::Kinematics...> kinematics;
  std::array<FrameMotion<Scalar>, N + 1> motion;  ///< [0] base, [i+1] distal frame of segment i
  std::array<BodyLoad<Scalar>, N> loads;  ///< per segment: its own body's load
  std::array<Wrench<Scalar>, N + 1> wrench;  ///< [i] at the base of segment i, [N] at the tip

  /// One output field per algorithm (as Pinocchio's data.tau, data.g, data.nle): rnea ->
  /// tau, gravity -> gravity_forces, bias -> bias_forces, mass_matrix_and_bias and aba ->
  /// nonlinear_forces (C qdot + G), aba and forward_dynamics -> qddot.
  typename ChainT::VectorQ tau, gravity_forces, bias_forces, nonlinear_forces, qdot_zero, unit, qddot;
  /// \var tau
  /// \brief Output of rnea(): \f$M\ddot q + C\dot q + G\f$.
  /// \var gravity_forces
  /// \brief Output of gravity(): G(q).
  /// \var bias_forces
  /// \brief Output of bias(): C(q, qdot) qdot (+ G with with_gravity).
  /// \var nonlinear_forces
  /// \brief Output of mass_matrix_and_bias(), forward_dynamics() and aba(): C qdot + G.
  /// \var qdot_zero
  /// \brief Scratch: a zero velocity (gravity(), mass_matrix()).
  /// \var unit
  /// \brief Scratch: a unit vector.
  /// \var qddot
  /// \brief Output of forward_dynamics() and aba(): the accelerations.
  typename ChainT::MatrixQ mass_matrix;  ///< output of mass_matrix(): M(q)
  typename ChainT::MatrixQ mass_factor;  ///< Cholesky factor of M (forward_dynamics)

  /// Per-segment scratch of aba (articulated_body.hpp).
  std::array<ArticulatedSegment<Scalar, detail::max_segment_nq<Segments...>()>, N> articulated;

  /// Outputs of rnea_derivatives() (dtau_dq, dtau_dqdot; d tau/d qddot is mass_matrix) and of
  /// aba_derivatives() (dqddot_dq, dqddot_dqdot, dqddot_dtau = M^-1), as Pinocchio's
  /// dtau_dq, dtau_dv, ddq_dq, ddq_dv, Minv.
  typename ChainT::MatrixQ dtau_dq, dtau_dqdot, dqddot_dq, dqddot_dqdot, dqddot_dtau;
  /// \var dtau_dq
  /// \brief Output of rnea_derivatives(): \f$\partial\tau/\partial q\f$.
  /// \var dtau_dqdot
  /// \brief Output of rnea_derivatives(): \f$\partial\tau/\partial\dot q\f$.
  /// \var dqddot_dq
  /// \brief Output of aba_derivatives(): \f$\partial\ddot q/\partial q\f$.
  /// \var dqddot_dqdot
  /// \brief Output of aba_derivatives(): \f$\partial\ddot q/\partial\dot q\f$.
  /// \var dqddot_dtau
  /// \brief Output of aba_derivatives(): \f$\partial\ddot q/\partial\tau = M^{-1}\f$.
  DerivativeWorkspace<ChainT> derivatives;
  /// \var derivatives
  /// \brief Scratch of the derivatives: the chain in an AutoDiff scalar and its workspace (fixed
  /// size: no heap).

  ChainData() = default;
  /// \brief Zero-initialised (what chain.make_data() returns); the chain's type sizes it.
  explicit ChainData(const ChainT&) {
    tau.setZero();
    gravity_forces.setZero();
    bias_forces.setZero();
    nonlinear_forces.setZero();
    qdot_zero.setZero();
    unit.setZero();
    qddot.setZero();
    mass_matrix.setZero();
    dtau_dq.setZero();
    dtau_dqdot.setZero();
    dqddot_dq.setZero();
    dqddot_dqdot.setZero();
    dqddot_dtau.setZero();
  }
  /// \return N, the number of segments.
  int num_segments() const { return N; }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

}  // namespace softrne
