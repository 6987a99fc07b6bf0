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
#include "softrne/chain/derivative_workspace.hpp"
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
  using Scalar = Scalar_;  ///< double, long double or an automatic-differentiation type
  using VectorQ = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;  ///< q, qdot, qddot, tau (dim nq)
  using MatrixQ = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;  ///< M (nq x nq)
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector of the scalar type
  using Data = DynamicChainData<Scalar>;        ///< the workspace type (make_data())
  using Segment = AnySegment<Scalar>;  ///< a std::variant of every segment type

  /// Gravitational acceleration \f$g^0\f$ in the base frame (eq. 16); for a hanging arm
  /// (base z down) set it to (0, 0, 9.81).
  Vector3 gravity = Vector3(Scalar(0), Scalar(0), Scalar(-9.81));
  /// Whether the CC joints' inertia rate enters (Consistent, default) or not (PaperFrozen,
  /// the paper's eq. 18).
  InertiaRate inertia_rate = InertiaRate::Consistent;

  /// \brief Appends a segment at the tip; `name` is used in messages and file columns.
  /// \tparam S A segment type of AnySegment (ConstantCurvatureJoint, RigidLink, ...).
  /// \param[in] segment The segment (copied into the chain).
  /// \param[in] name Its name (robot files: the segment's "name").
  template <class S>
  void add(S segment, std::string name = {}) {
    offsets_.push_back(nq_);
    nq_ += S::nq;
    segments_.emplace_back(std::move(segment));
    names_.push_back(std::move(name));
  }

  /// \return The number of segments, base to tip.
  int num_segments() const { return static_cast<int>(segments_.size()); }
  /// \return nq, the size of q, qdot, qddot and tau.
  int num_coordinates() const { return nq_; }
  /// \param[in] i A segment index. \return The index of segment i's first coordinate
  /// in q.
  int q_offset(int i) const { return offsets_[static_cast<std::size_t>(i)]; }
  /// \param[in] i A segment index (0 = base). \return Segment i.
  const Segment& segment(int i) const { return segments_[static_cast<std::size_t>(i)]; }
  /// \param[in] i A segment index (0 = base). \return Segment i, to change its
  /// constants (not while another thread evaluates the chain).
  Segment& segment(int i) { return segments_[static_cast<std::size_t>(i)]; }
  /// \param[in] i A segment index. \return The name given to add().
  const std::string& name(int i) const { return names_[static_cast<std::size_t>(i)]; }
  /// \return A workspace for this chain, sized once (one per thread); the
  /// algorithms allocate nothing after it.
  Data make_data() const { return Data(*this); }

  /// \brief Throws std::invalid_argument naming the algorithm, the argument and both sizes
  /// unless `size` == num_coordinates(). Always on, also in Release: a runtime chain is built
  /// from a user's robot file, so its size is known only at run time (the compile-time
  /// Chain<...> checks fixed-size arguments when it compiles).
  /// \param[in] algorithm The algorithm's name, for the message.
  /// \param[in] argument The argument's name, for the message.
  /// \param[in] size The argument's size.
  /// \throws std::invalid_argument if size != num_coordinates().
  void check_argument(const char* algorithm, const char* argument, Eigen::Index size) const {
    if (size != nq_) throw_size_mismatch(algorithm, argument, size);
  }
  /// \brief Throws std::invalid_argument unless `data` was made by make_data() of a chain with
  /// this one's segments. Always on, like check_argument().
  /// \param[in] data The workspace to check.
  /// \throws std::invalid_argument if data has another number of segments or coordinates.
  void check_data(const Data& data) const {
    // The test inline, the message out of line (throw_data_mismatch): every algorithm on a
    // runtime chain starts here, and a 6-joint mass_matrix costs a few hundred instructions.
    if (data.kinematics.size() != segments_.size() || static_cast<int>(data.tau.size()) != nq_)
      throw_data_mismatch(data.kinematics.size(), data.tau.size());
  }

  /// \brief Calls f(segment, kinematics, index, q_offset) base to tip.
  /// \param[in,out] data The workspace whose per-segment kinematics f receives.
  /// \param[in] f A generic callable (each segment type is visited with its own type).
  /// \throws std::invalid_argument if data was made for another chain.
  template <class F>
  void forward(Data& data, F&& f) const {
    check_data(data);
    for (int i = 0; i < num_segments(); ++i) visit(data, f, i);
  }
  /// \brief Calls f(segment, kinematics, index, q_offset) tip to base.
  /// \param[in,out] data The workspace whose per-segment kinematics f receives.
  /// \param[in] f A generic callable (each segment type is visited with its own type).
  /// \throws std::invalid_argument if data was made for another chain.
  template <class F>
  void backward(Data& data, F&& f) const {
    check_data(data);
    for (int i = num_segments() - 1; i >= 0; --i) visit(data, f, i);
  }

  /// \brief Calls f(segment, kinematics, index, q_offset) for segment i alone.
  /// \param[in,out] data The workspace whose segment-i kinematics f receives.
  /// \param[in] i The segment's index, 0 <= i < num_segments().
  /// \param[in] f A generic callable (the segment is visited with its own type).
  /// \throws std::invalid_argument if data was made for another chain.
  template <class F>
  void visit_segment(Data& data, int i, F&& f) const {
    check_data(data);
    visit(data, f, i);
  }

  /// \brief The same chain in another scalar type (e.g. an AutoDiff scalar for derivatives).
  /// \tparam NewScalar The new scalar type.
  /// \return A copy with every constant converted.
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
          Kin* kin = std::get_if<Kin>(&data.kinematics[k]);
          if (kin == nullptr) throw_segment_mismatch(i);
          f(seg, *kin, i, offsets_[k]);
        },
        segments_[k]);
  }
  // The messages of check_argument(), check_data() and visit(), out of line so that the
  // checks themselves inline into the algorithms as a compare and a branch.
  [[noreturn]] EIGEN_DONT_INLINE void throw_size_mismatch(const char* algorithm,
                                                          const char* argument,
                                                          Eigen::Index size) const {
    throw std::invalid_argument(std::string("softrne::") + algorithm + ": " + argument + " has " +
                                std::to_string(size) + " entries; the chain has " +
                                std::to_string(nq_) + " coordinates");
  }
  [[noreturn]] EIGEN_DONT_INLINE void throw_data_mismatch(std::size_t segments,
                                                          Eigen::Index coordinates) const {
    throw std::invalid_argument(
        "softrne::DynamicChain: this Data was made for another chain (" + std::to_string(segments) +
        " segments, " + std::to_string(coordinates) + " coordinates; this chain has " +
        std::to_string(segments_.size()) + " and " + std::to_string(nq_) + "; call make_data())");
  }
  [[noreturn]] static EIGEN_DONT_INLINE void throw_segment_mismatch(int i) {
    throw std::invalid_argument(
        "softrne::DynamicChain: this Data was made for another chain (segment " +
        std::to_string(i) + " has another type; call make_data())");
  }
  std::vector<Segment> segments_;
  std::vector<std::string> names_;
  std::vector<int> offsets_;
  int nq_ = 0;
};

/// \brief Per-evaluation workspace of a runtime chain, sized once by the chain.
template <class Scalar>
struct DynamicChainData {
  using VectorQ = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;  ///< as DynamicChain::VectorQ
  using MatrixQ = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;  ///< as the chain's

  /// Per segment: what compute_kinematics() computed (rotations, Jacobians, inertias).
  std::vector<AnySegmentKinematics<Scalar>> kinematics;
  std::vector<FrameMotion<Scalar>> motion;  ///< [0] base, [i+1] distal frame of segment i
  std::vector<BodyLoad<Scalar>> loads;      ///< per segment: its own body's load
  std::vector<Wrench<Scalar>> wrench;  ///< [i] at the base of segment i, [N] at the tip

  /// One output field per algorithm (as Pinocchio's data.tau, data.g, data.nle): rnea ->
  /// tau, gravity -> gravity_forces, bias -> bias_forces, mass_matrix_and_bias and aba ->
  /// nonlinear_forces (C qdot + G), aba and forward_dynamics -> qddot.
  VectorQ tau, gravity_forces, bias_forces, nonlinear_forces, qdot_zero, unit, qddot;
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
  MatrixQ mass_matrix;  ///< output of mass_matrix() and mass_matrix_and_bias(): M(q)
  MatrixQ mass_factor;  ///< Cholesky factor of M (forward_dynamics)

  /// Largest nq of a segment type (sizes `articulated`).
  static constexpr int max_segment_nq = detail::variant_max_nq<AnySegment<Scalar>>::value;
  /// Per-segment scratch of aba (articulated_body.hpp), one per segment.
  std::vector<ArticulatedSegment<Scalar, max_segment_nq>> articulated;

  /// Outputs of rnea_derivatives() (dtau_dq, dtau_dqdot; d tau/d qddot is mass_matrix) and of
  /// aba_derivatives() (dqddot_dq, dqddot_dqdot, dqddot_dtau = M^-1), as Pinocchio's
  /// dtau_dq, dtau_dv, ddq_dq, ddq_dv, Minv. Sized nq x nq by the first call (allocated once
  /// then, so that a Data never used for derivatives does not carry five nq x nq matrices).
  MatrixQ dtau_dq, dtau_dqdot, dqddot_dq, dqddot_dqdot, dqddot_dtau;
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
  DerivativeWorkspace<DynamicChain<Scalar>> derivatives;
  /// \var derivatives
  /// \brief Scratch of the derivatives: the chain in an AutoDiff scalar and its workspace, built
  /// by the first call (allocated once then).

  DynamicChainData() = default;
  /// \brief Sized for `chain` (what chain.make_data() returns).
  /// \param[in] chain The chain this workspace serves.
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
  /// \return The number of segments of the chain this was made for.
  int num_segments() const { return static_cast<int>(kinematics.size()); }
};

}  // namespace softrne
