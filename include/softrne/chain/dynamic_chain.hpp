#pragma once
/// \file
/// \brief Chain whose segments are chosen at run time (e.g. read from a robot file).

#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "softrne/chain/articulated_workspace.hpp"
#include "softrne/chain/motion.hpp"
#include "softrne/config.hpp"
#include "softrne/segments/segment_list.hpp"

namespace softrne {

template <class Scalar>
struct DynamicChainData;

/// \brief A serial chain of `AnySegment`s, base to tip. Same algorithms as `Chain<...>`: the
/// traversal visits each variant and calls the same generic step bodies.
///
/// Build it with `add(...)`, then `make_data()` once; evaluation allocates nothing.
template <class Scalar_>
class DynamicChain {
 public:
  using Scalar = Scalar_;
  using VectorQ = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  using MatrixQ = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Data = DynamicChainData<Scalar>;
  using Segment = AnySegment<Scalar>;

  Vector3 gravity = Vector3(Scalar(0), Scalar(0), Scalar(-9.81));  ///< in the base frame
  InertiaRate inertia_rate = InertiaRate::Consistent;

  /// \brief Appends a segment at the tip; `name` is used in messages and file columns.
  template <class S>
  void add(S segment, std::string name = {}) {
    offsets_.push_back(nq_);
    nq_ += S::nq;
    segments_.emplace_back(std::move(segment));
    names_.push_back(std::move(name));
  }

  int num_segments() const { return static_cast<int>(segments_.size()); }
  int num_coordinates() const { return nq_; }
  int q_offset(int i) const { return offsets_[static_cast<std::size_t>(i)]; }
  const Segment& segment(int i) const { return segments_[static_cast<std::size_t>(i)]; }
  Segment& segment(int i) { return segments_[static_cast<std::size_t>(i)]; }
  const std::string& name(int i) const { return names_[static_cast<std::size_t>(i)]; }
  Data make_data() const { return Data(*this); }

  /// \brief Throws std::invalid_argument naming the algorithm, the argument and both sizes
  /// unless `size` == num_coordinates(). Always on, also in Release: a runtime chain is built
  /// from a user's robot file, so its size is known only at run time (the compile-time
  /// Chain<...> checks fixed-size arguments when it compiles).
  void check_argument(const char* algorithm, const char* argument, Eigen::Index size) const {
    if (size != nq_)
      throw std::invalid_argument(std::string("softrne::") + algorithm + ": " + argument + " has " +
                                  std::to_string(size) + " entries; the chain has " +
                                  std::to_string(nq_) + " coordinates");
  }
  /// \brief Throws std::invalid_argument unless `data` was made by make_data() of a chain with
  /// this one's segments. Always on, like check_argument().
  void check_data(const Data& data) const {
    if (data.kinematics.size() != segments_.size() || static_cast<int>(data.tau.size()) != nq_)
      throw std::invalid_argument(
          "softrne::DynamicChain: this Data was made for another chain (" +
          std::to_string(data.kinematics.size()) + " segments, " + std::to_string(data.tau.size()) +
          " coordinates; this chain has " + std::to_string(segments_.size()) + " and " +
          std::to_string(nq_) + "; call make_data())");
  }

  /// \brief Calls f(segment, kinematics, index, q_offset) base to tip.
  template <class F>
  void forward(Data& data, F&& f) const {
    check_data(data);
    for (int i = 0; i < num_segments(); ++i) visit(data, f, i);
  }
  /// \brief Calls f(segment, kinematics, index, q_offset) tip to base.
  template <class F>
  void backward(Data& data, F&& f) const {
    check_data(data);
    for (int i = num_segments() - 1; i >= 0; --i) visit(data, f, i);
  }

  template <class NewScalar>
  DynamicChain<NewScalar> cast() const {
    DynamicChain<NewScalar> c;
    for (int i = 0; i < num_segments(); ++i)
      std::visit([&](const auto& s) { c.add(s.template cast<NewScalar>(), name(i)); },
                 segment(i));
    c.gravity = gravity.template cast<NewScalar>();
    c.inertia_rate = inertia_rate;
    return c;
  }

 private:
  template <class F>
  void visit(Data& data, F& f, int i) const {
    const auto k = static_cast<std::size_t>(i);
    std::visit(
        [&](const auto& seg) {
          using Kin = typename std::decay_t<decltype(seg)>::Kinematics;
          // Same number of segments and coordinates but other types (a Data made for a
          // chain built in another order): a message here rather than bad_variant_access.
          if (!std::holds_alternative<Kin>(data.kinematics[k]))
            throw std::invalid_argument(
                "softrne::DynamicChain: this Data was made for another chain (segment " +
                std::to_string(i) + " has another type; call make_data())");
          f(seg, std::get<Kin>(data.kinematics[k]), i, offsets_[k]);
        },
        segments_[k]);
  }
  std::vector<Segment> segments_;
  std::vector<std::string> names_;
  std::vector<int> offsets_;
  int nq_ = 0;
};

/// \brief Per-evaluation workspace of a runtime chain, sized once by the chain.
template <class Scalar>
struct DynamicChainData {
  using VectorQ = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  using MatrixQ = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

  std::vector<AnySegmentKinematics<Scalar>> kinematics;
  std::vector<FrameMotion<Scalar>> motion;
  std::vector<BodyLoad<Scalar>> loads;
  std::vector<Wrench<Scalar>> wrench;
  /// One output field per algorithm (as Pinocchio's data.tau, data.g, data.nle): rnea ->
  /// tau, gravity -> gravity_forces, bias -> bias_forces, mass_matrix_and_bias and aba ->
  /// nonlinear_forces (C qdot + G), aba and forward_dynamics -> qddot.
  VectorQ tau, gravity_forces, bias_forces, nonlinear_forces, qdot_zero, unit, qddot;
  MatrixQ mass_matrix;
  MatrixQ mass_factor;  ///< Cholesky factor of M (forward_dynamics)
  /// Per-segment scratch of aba (articulated_body.hpp), one per segment.
  static constexpr int max_segment_nq = detail::variant_max_nq<AnySegment<Scalar>>::value;
  std::vector<ArticulatedSegment<Scalar, max_segment_nq>> articulated;

  DynamicChainData() = default;
  explicit DynamicChainData(const DynamicChain<Scalar>& chain) {
    const auto n = static_cast<std::size_t>(chain.num_segments());
    const int nq = chain.num_coordinates();
    kinematics.reserve(n);
    for (int i = 0; i < chain.num_segments(); ++i)
      std::visit(
          [&](const auto& seg) {
            kinematics.emplace_back(typename std::decay_t<decltype(seg)>::Kinematics{});
          },
          chain.segment(i));
    motion.resize(n + 1);
    loads.resize(n);
    wrench.resize(n + 1);
    articulated.resize(n);
    tau = VectorQ::Zero(nq);
    gravity_forces = VectorQ::Zero(nq);
    bias_forces = VectorQ::Zero(nq);
    nonlinear_forces = VectorQ::Zero(nq);
    qdot_zero = VectorQ::Zero(nq);
    unit = VectorQ::Zero(nq);
    qddot = VectorQ::Zero(nq);
    mass_matrix = MatrixQ::Zero(nq, nq);
    mass_factor = MatrixQ::Zero(nq, nq);
  }
  int num_segments() const { return static_cast<int>(kinematics.size()); }
};

}  // namespace softrne
