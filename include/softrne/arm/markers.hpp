#pragma once
/// \file
/// \brief Motion-capture markers of an arm (issue 19): where each marker of the robot file is
/// in the base frame for simulated configurations, and the rigid transform of the
/// motion-capture frame that best maps those positions onto measured ones.

#include <cmath>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "softrne/config.hpp"
#include "softrne/algorithms/kinematics.hpp"
#include "softrne/arm/arm_description.hpp"

namespace softrne {

/// \brief Index in the chain (= in spec.segments) of the segment that carries each marker.
/// \param[in] d The arm.
/// \return One index per marker of d.spec.markers.
/// \throws std::invalid_argument if a marker names no segment (robot files are validated, so
///   only a spec built in code can).
inline std::vector<int> marker_segments(const ArmDescription& d) {
  std::vector<int> out;
  for (const auto& m : d.spec.markers) {
    int found = -1;
    for (std::size_t s = 0; s < d.spec.segments.size(); ++s)
      if (io::segment_name(d.spec.segments[s]) == m.segment) found = static_cast<int>(s);
    if (found < 0) throw std::invalid_argument("marker '" + m.name + "': no segment is named '" + m.segment + "'");
    out.push_back(found);
  }
  return out;
}

/// \brief The arm's reach: the sum of its CC joints' arc lengths and its links' lengths.
/// \param[in] d The arm.
/// \return The reach, m.
inline double arm_reach(const ArmDescription& d) {
  double L = 0;
  for (const auto& seg : d.spec.segments) {
    if (const auto* cc = std::get_if<io::CCJointSpec>(&seg)) L += cc->height;
    if (const auto* rl = std::get_if<io::RigidLinkSpec>(&seg)) L += rl->length;
  }
  return L;
}

/// \brief Positions of the arm's markers in its base frame, for each row of `states` (its first
/// nq columns are the configuration q; simulated states or configurations alone): the
/// segment's distal placement (distal_placement(), eqs. 2 and 4) applied to the marker's offset.
/// \param[in] d The arm (d.spec.markers).
/// \param[in] states N x (at least nq).
/// \return N x 3M, columns x, y, z of each marker in order, m.
SOFTRNE_SIM_INLINE Eigen::MatrixXd marker_positions(const ArmDescription& d,
                                                    const Eigen::MatrixXd& states)
#if SOFTRNE_SIM_BODIES
{
  const std::vector<int> seg = marker_segments(d);
  const auto M = static_cast<Eigen::Index>(seg.size());
  Eigen::MatrixXd out(states.rows(), 3 * M);
  if (M == 0 || states.rows() == 0) return out;
  if (states.cols() < d.nq) throw std::invalid_argument("marker_positions: states have fewer columns than nq");
  const DynamicChain<double> chain = d.make_chain<double>();
  auto data = chain.make_data();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(d.nq);
  for (Eigen::Index i = 0; i < states.rows(); ++i) {
    compute_kinematics(chain, data, states.row(i).head(d.nq).transpose(), zero);
    for (Eigen::Index k = 0; k < M; ++k) {
      const Placement<double> X = distal_placement(chain, data, seg[static_cast<std::size_t>(k)]);
      out.row(i).segment<3>(3 * k) = (X.p + X.R * d.spec.markers[static_cast<std::size_t>(k)].offset).transpose();
    }
  }
  return out;
}
#else
;
#endif

/// \brief A rigid transform from the arm's base frame to the motion-capture frame:
/// y = R x + t.
struct CaptureFrame {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< rotation (base axes in capture coordinates)
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      ///< the base origin in capture coordinates, m

  /// \brief Maps base-frame positions into the capture frame.
  /// \param[in] base N x 3M positions (x, y, z of each marker), base frame, m.
  /// \return The same positions in the capture frame.
  Eigen::MatrixXd apply(const Eigen::MatrixXd& base) const {
    Eigen::MatrixXd y(base.rows(), base.cols());
    for (Eigen::Index i = 0; i < base.rows(); ++i)
      for (Eigen::Index k = 0; k + 2 < base.cols(); k += 3)
        y.row(i).segment<3>(k) = (R * base.row(i).segment<3>(k).transpose() + t).transpose();
    return y;
  }
};

/// \brief The rotation and translation that best map base-frame marker positions onto measured
/// capture-frame ones in least squares over the rows where `use` is true (all if empty): the
/// Kabsch solution (SVD of the points' cross-covariance, with the reflection removed).
///
/// Used inside the fit as a variable projection: for every candidate of the physical
/// parameters the frame is solved in closed form, so the optimiser searches only the physics.
/// \param[in] base N x 3M simulated positions, base frame, m.
/// \param[in] measured N x 3M measured positions, capture frame, m.
/// \param[in] use Rows to use (size N), or empty for all.
/// \return The frame; identity rotation if the points do not determine it (fewer than three
///   non-collinear points are only as good as they are: the SVD picks one).
SOFTRNE_SIM_INLINE CaptureFrame fit_capture_frame(const Eigen::MatrixXd& base,
                                                  const Eigen::MatrixXd& measured,
                                                  const std::vector<bool>& use = {})
#if SOFTRNE_SIM_BODIES
{
  CaptureFrame f;
  Eigen::Vector3d cb = Eigen::Vector3d::Zero(), cm = Eigen::Vector3d::Zero();
  double n = 0;
  for (Eigen::Index i = 0; i < base.rows(); ++i) {
    if (!use.empty() && !use[static_cast<std::size_t>(i)]) continue;
    for (Eigen::Index k = 0; k + 2 < base.cols(); k += 3) {
      cb += base.row(i).segment<3>(k).transpose();
      cm += measured.row(i).segment<3>(k).transpose();
      n += 1;
    }
  }
  if (n == 0) return f;
  cb /= n;
  cm /= n;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // sum (x - cb)(y - cm)^T
  for (Eigen::Index i = 0; i < base.rows(); ++i) {
    if (!use.empty() && !use[static_cast<std::size_t>(i)]) continue;
    for (Eigen::Index k = 0; k + 2 < base.cols(); k += 3)
      H += (base.row(i).segment<3>(k).transpose() - cb) * (measured.row(i).segment<3>(k) - cm.transpose());
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  f.R = svd.matrixV() * D * svd.matrixU().transpose();
  f.t = cm - f.R * cb;
  return f;
}
#else
;
#endif

}  // namespace softrne
