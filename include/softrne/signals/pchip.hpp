#pragma once
/// \file
/// \brief PchipSignal: the name under which PCHIP interpolation of sampled inputs first came;
/// it is now a mode of InputSignal (Interpolation::pchip, input_signal.hpp), where the slopes
/// and the evaluation live once.

#include <Eigen/Core>

#include "softrne/signals/input_signal.hpp"

namespace softrne::signals {

/// \brief An InputSignal with Interpolation::pchip (piecewise cubic Hermite, Fritsch-Carlson
/// slopes), kept for code written against the old class: the same values, one implementation.
class PchipSignal : public InputSignal {
 public:
  /// \brief The interpolant of N samples.
  /// \param[in] t The N sample times, s, strictly increasing.
  /// \param[in] values N x P, one row per sample.
  /// \throws std::invalid_argument as InputSignal's constructor.
  PchipSignal(const Eigen::VectorXd& t, const Eigen::MatrixXd& values)
      : InputSignal(t, values, Interpolation::pchip) {}
};

}  // namespace softrne::signals
