#pragma once
/// \file
/// \brief Compile-time chain of heterogeneous segments.

#include <array>
#include <tuple>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "softrne/chain/articulated_workspace.hpp"
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
  using Scalar = typename std::tuple_element_t<0, std::tuple<Segments...>>::Scalar;
  static_assert((std::is_same_v<Scalar, typename Segments::Scalar> && ...),
                "softrne::Chain: all segments must use the same Scalar type");
  static constexpr int num_segments = static_cast<int>(sizeof...(Segments));
  static constexpr int nq = (0 + ... + Segments::nq);
  using VectorQ = Eigen::Matrix<Scalar, nq, 1>;
  using MatrixQ = Eigen::Matrix<Scalar, nq, nq>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Data = ChainData<Chain>;

  std::tuple<Segments...> segments;
  Vector3 gravity = Vector3(Scalar(0), Scalar(0), Scalar(-9.81));  ///< in the base frame
  InertiaRate inertia_rate = InertiaRate::Consistent;

  Chain() { (check_segment<Segments>(), ...); }
  explicit Chain(Segments... segs) : segments(std::move(segs)...) {
    (check_segment<Segments>(), ...);
  }

  int num_coordinates() const { return nq; }
  Data make_data() const { return Data(*this); }

  /// \brief A fixed-size argument of another size does not compile (detail::check_argument);
  /// a dynamic-size one (a VectorXd passed to a fixed chain) is checked in debug builds, as
  /// Eigen checks sizes. The hot path of a controller pays nothing.
  void check_argument(const char*, const char*, Eigen::Index size) const {
    SOFTRNE_ASSERT(size == nq, "softrne::Chain: an argument's size is not the chain's nq");
    (void)size;
  }
  /// \brief Nothing to check: the Data type belongs to this chain type alone.
  void check_data(const Data&) const {}

  /// Offset of segment I's coordinates in q.
  template <std::size_t I>
  static constexpr int q_offset() {
    constexpr int sizes[] = {Segments::nq...};
    int o = 0;
    for (std::size_t k = 0; k < I; ++k) o += sizes[k];
    return o;
  }

  /// \brief Calls f(segment, kinematics, index, q_offset) base to tip.
  template <class DataT, class F>
  void forward(DataT& data, F&& f) const {
    forward_impl(data, f, std::index_sequence_for<Segments...>{});
  }
  /// \brief Calls f(segment, kinematics, index, q_offset) tip to base.
  template <class DataT, class F>
  void backward(DataT& data, F&& f) const {
    backward_impl(data, f, std::index_sequence_for<Segments...>{});
  }

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
  using ChainT = Chain<Segments...>;
  using Scalar = typename ChainT::Scalar;
  static constexpr int N = ChainT::num_segments;

  std::tuple<typename Segments::Kinematics...> kinematics;
  std::array<FrameMotion<Scalar>, N + 1> motion;  ///< [0] base, [i+1] distal frame of segment i
  std::array<BodyLoad<Scalar>, N> loads;
  std::array<Wrench<Scalar>, N + 1> wrench;  ///< [i] at the base of segment i, [N] at the tip
  /// One output field per algorithm (as Pinocchio's data.tau, data.g, data.nle): rnea ->
  /// tau, gravity -> gravity_forces, bias -> bias_forces, mass_matrix_and_bias and aba ->
  /// nonlinear_forces (C qdot + G), aba and forward_dynamics -> qddot.
  typename ChainT::VectorQ tau, gravity_forces, bias_forces, nonlinear_forces, qdot_zero, unit, qddot;
  typename ChainT::MatrixQ mass_matrix;
  typename ChainT::MatrixQ mass_factor;  ///< Cholesky factor of M (forward_dynamics)
  /// Per-segment scratch of aba (articulated_body.hpp).
  std::array<ArticulatedSegment<Scalar, detail::max_segment_nq<Segments...>()>, N> articulated;

  ChainData() = default;
  explicit ChainData(const ChainT&) {
    tau.setZero();
    gravity_forces.setZero();
    bias_forces.setZero();
    nonlinear_forces.setZero();
    qdot_zero.setZero();
    unit.setZero();
    qddot.setZero();
    mass_matrix.setZero();
  }
  int num_segments() const { return N; }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

}  // namespace softrne
