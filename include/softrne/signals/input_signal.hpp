#pragma once
/// \file
/// \brief A sampled input signal u(t) (pressures, torques): zero-order hold, linear or
/// shape-preserving cubic (PCHIP) interpolation, clamped outside the sampled range. Eigen only.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace softrne::signals {

/// \brief How an InputSignal is evaluated between two sample times.
enum class Interpolation {
  zero_order_hold,  ///< \f$u(t) = u_i\f$ for \f$t_i \le t < t_{i+1}\f$ (right-continuous steps)
  linear,           ///< \f$u(t) = u_i + (t - t_i)\,(u_{i+1} - u_i)/(t_{i+1} - t_i)\f$
  /// Piecewise cubic Hermite with Fritsch-Carlson slopes (PCHIP): continuous first
  /// derivative, no overshoot at steps, exact on linear data. Why it is the simulator's
  /// default: recorded pressures are noisy samples of a continuous signal; linear
  /// interpolation puts a kink at every sample and zero-order hold a jump, and the
  /// integrator's error test shrinks the step to resolve each one (tens of thousands of steps
  /// for a 10 s, 100 Hz record). PCHIP removes both at no cost in fidelity.
  pchip
};

/// \brief Which one-sided limit to return exactly at a sample time. Only a
/// zero-order-hold signal is discontinuous, so only it is affected.
///
/// An ODE integrator that stops at a breakpoint \f$t_b\f$ evaluates the
/// right-hand side at \f$t_b\f$ itself on the last step of the segment that
/// ends there; that step must see the value held *before* the jump
/// (Side::left), the first step of the next segment the value after it
/// (Side::right, the default). See softrne::sim::integrate's set_segment hint.
enum class Side { right, left };

/// \brief A cursor into an InputSignal's sample times, for reentrant lookups
/// (one cursor per thread or per consumer).
struct SignalCursor {
  Eigen::Index index = 0;  ///< a sample index near the last query
};

/// \brief A sampled vector signal \f$u(t) \in \mathbb{R}^P\f$ given at \f$N\f$
/// strictly increasing (possibly irregular) sample times.
///
/// Invariants: at least one sample; times strictly increasing and finite;
/// values finite. Outside \f$[t_0, t_{N-1}]\f$ the signal is clamped to the
/// first or last sample. Evaluation allocates nothing. A lookup is O(1) when
/// consecutive queries are monotone and close (the cursor walks a few samples),
/// and O(log N) otherwise (binary search).
///
/// The non-const value() uses a cursor stored in the object and is therefore
/// not safe to call concurrently on one object; the const overload taking a
/// SignalCursor is.
class InputSignal {
 public:
  InputSignal() = default;

  /// \brief Builds the signal from sample times (size N) and values (N x P,
  /// one row per sample). Throws std::invalid_argument when an invariant fails.
  /// \param[in] times The N sample times, s, strictly increasing.
  /// \param[in] values N x P, one row per sample.
  /// \param[in] interpolation Zero-order hold (default), linear or PCHIP between samples.
  /// \throws std::invalid_argument if there is no sample, the sizes disagree, a value is
  ///   not finite or the times do not increase strictly.
  InputSignal(const Eigen::Ref<const Eigen::VectorXd>& times,
              const Eigen::Ref<const Eigen::MatrixXd>& values,
              Interpolation interpolation = Interpolation::zero_order_hold)
      : times_(times), samples_(values.transpose()), interpolation_(interpolation) {
    if (times.size() < 1) throw std::invalid_argument("InputSignal: no samples");
    if (values.rows() != times.size())
      throw std::invalid_argument("InputSignal: values has " + std::to_string(values.rows()) +
                                  " rows but there are " + std::to_string(times.size()) +
                                  " sample times");
    if (!times.allFinite() || !values.allFinite())
      throw std::invalid_argument("InputSignal: non-finite sample time or value");
    for (Eigen::Index i = 1; i < times.size(); ++i)
      if (!(times[i] > times[i - 1]))
        throw std::invalid_argument(
            "InputSignal: sample times are not strictly increasing at index " + std::to_string(i));
    if (interpolation == Interpolation::pchip) compute_pchip_slopes();
  }

  /// \return The number of channels P.
  Eigen::Index size() const { return samples_.rows(); }
  /// \return The number of samples N.
  Eigen::Index num_samples() const { return times_.size(); }
  /// \return The first sample time.
  double t_begin() const { return times_[0]; }
  /// \return The last sample time.
  double t_end() const { return times_[times_.size() - 1]; }
  /// \return The sample times (N).
  const Eigen::VectorXd& times() const { return times_; }
  /// \brief Sample i as a contiguous column (P).
  /// \param[in] i A sample index, 0 <= i < N.
  /// \return A view of the sample's P values.
  auto sample(Eigen::Index i) const { return samples_.col(i); }
  /// \return How values between samples are obtained.
  Interpolation interpolation() const { return interpolation_; }

  /// \brief Writes \f$u(t)\f$ into `out` (size P; a vector or a block such as
  /// `x.segment(i, P)`), using the object's cursor.
  /// \param[in] t Time, s (clamped to the samples' range).
  /// \param[out] out The P values at t.
  /// \param[in] side At a jump of a zero-order hold: the value after it (right) or before.
  template <class Derived>
  void value(double t, Eigen::MatrixBase<Derived>& out, Side side = Side::right) {
    evaluate(t, out, cursor_, side);
  }
  /// \brief As value(t, out, side) for a temporary block such as `x.segment(i, P)`.
  /// \param[in] t Time, s.
  /// \param[out] out The P values at t.
  /// \param[in] side The side of a jump.
  template <class Derived>
  void value(double t, Eigen::MatrixBase<Derived>&& out, Side side = Side::right) {
    evaluate(t, out, cursor_, side);
  }

  /// \brief Writes \f$u(t)\f$ into `out` (size P), using the caller's cursor.
  /// \param[in] t Time, s (clamped to the samples' range).
  /// \param[out] out The P values at t.
  /// \param[in,out] cursor The caller's cursor (one per thread).
  /// \param[in] side The side of a jump.
  template <class Derived>
  void value(double t, Eigen::MatrixBase<Derived>& out, SignalCursor& cursor,
             Side side = Side::right) const {
    evaluate(t, out, cursor, side);
  }
  /// \brief As value(t, out, cursor, side) for a temporary block.
  /// \param[in] t Time, s.
  /// \param[out] out The P values at t.
  /// \param[in,out] cursor The caller's cursor.
  /// \param[in] side The side of a jump.
  template <class Derived>
  void value(double t, Eigen::MatrixBase<Derived>&& out, SignalCursor& cursor,
             Side side = Side::right) const {
    evaluate(t, out, cursor, side);
  }

  /// \brief Times where the signal is not smooth, for an ODE integrator to stop at.
  ///
  /// Zero-order hold: the sample times \f$t_i\f$ (i >= 1) where the value jumps,
  /// \f$\|u_i - u_{i-1}\|_\infty > \f$ `tolerance`. Linear: the sample times where
  /// the slope changes by more than `tolerance` (infinity norm), counting the
  /// zero slope of the clamped extension before \f$t_0\f$ and after \f$t_{N-1}\f$. PCHIP:
  /// none (its first derivative is continuous inside the range; at the ends the clamped
  /// extension meets it with the end slope, which integrators cross like any other change).
  /// With densely sampled data almost every sample is a breakpoint; stopping at
  /// each one costs a solver restart, so pass a tolerance or thin the list.
  /// \param[in] tolerance Smallest jump (or slope change) that counts.
  /// \return The breakpoint times, increasing.
  std::vector<double> breakpoints(double tolerance = 0.0) const {
    std::vector<double> result;
    const Eigen::Index n = times_.size();
    if (interpolation_ == Interpolation::pchip) return result;
    if (interpolation_ == Interpolation::zero_order_hold) {
      for (Eigen::Index i = 1; i < n; ++i)
        if ((samples_.col(i) - samples_.col(i - 1)).cwiseAbs().maxCoeff() > tolerance)
          result.push_back(times_[i]);
      return result;
    }
    // Slope on interval i is (u_{i+1} - u_i) / (t_{i+1} - t_i); zero outside.
    auto slope_change_exceeds = [&](Eigen::Index i) {  // kink at sample i
      double worst = 0.0;
      for (Eigen::Index c = 0; c < samples_.rows(); ++c) {
        const double before =
            i > 0 ? (samples_(c, i) - samples_(c, i - 1)) / (times_[i] - times_[i - 1]) : 0.0;
        const double after =
            i + 1 < n ? (samples_(c, i + 1) - samples_(c, i)) / (times_[i + 1] - times_[i]) : 0.0;
        worst = std::max(worst, std::abs(after - before));
      }
      return worst > tolerance;
    };
    for (Eigen::Index i = 0; i < n; ++i)
      if (slope_change_exceeds(i)) result.push_back(times_[i]);
    return result;
  }

 private:
  // Outputs are taken by lvalue or rvalue reference, not by Eigen's usual
  // `const MatrixBase&` + const_cast: GCC 12 warns (-Wmaybe-uninitialized) when
  // an uninitialised vector is passed by const reference.
  template <class Derived>
  void evaluate(double t, Eigen::MatrixBase<Derived>& u, SignalCursor& cursor, Side side) const {
    const Eigen::Index n = times_.size();
    if (interpolation_ == Interpolation::zero_order_hold) {
      u = samples_.col(locate(t, side, cursor));
      return;
    }
    // Linear and PCHIP: continuous, so the side does not matter.
    if (!(t > times_[0])) {  // also catches NaN: clamp to the first sample
      u = samples_.col(0);
      return;
    }
    if (t >= times_[n - 1]) {
      u = samples_.col(n - 1);
      return;
    }
    const Eigen::Index i = locate(t, Side::right, cursor);  // t_i <= t < t_{i+1}
    const double h = times_[i + 1] - times_[i], s = (t - times_[i]) / h;
    if (interpolation_ == Interpolation::linear) {
      u = (1.0 - s) * samples_.col(i) + s * samples_.col(i + 1);
      return;
    }
    // Cubic Hermite basis on [t_i, t_{i+1}] with the slopes m_i, m_{i+1}.
    const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s);
    const double h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
    u = h00 * samples_.col(i) + h10 * h * slopes_.col(i) + h01 * samples_.col(i + 1) +
        h11 * h * slopes_.col(i + 1);
  }

  /// Fritsch-Carlson slopes (Fritsch and Carlson, SIAM J. Numer. Anal. 17, 1980; the
  /// three-point weighted harmonic mean of Fritsch and Butland, as MATLAB's and scipy's
  /// pchip): zero at a local extremum of the data, one-sided secants at the ends.
  void compute_pchip_slopes() {
    const Eigen::Index n = times_.size(), channels = samples_.rows();
    slopes_ = Eigen::MatrixXd::Zero(channels, n);
    if (n < 2) return;
    for (Eigen::Index c = 0; c < channels; ++c) {
      auto secant = [&](Eigen::Index i) {  // on [t_i, t_{i+1}]
        return (samples_(c, i + 1) - samples_(c, i)) / (times_[i + 1] - times_[i]);
      };
      slopes_(c, 0) = secant(0);
      slopes_(c, n - 1) = secant(n - 2);
      for (Eigen::Index i = 1; i + 1 < n; ++i) {
        const double d0 = secant(i - 1), d1 = secant(i);
        if (d0 * d1 <= 0) continue;  // local extremum: flat
        const double h0 = times_[i] - times_[i - 1], h1 = times_[i + 1] - times_[i];
        const double w1 = 2 * h1 + h0, w2 = h1 + 2 * h0;
        slopes_(c, i) = (w1 + w2) / (w1 / d0 + w2 / d1);  // weighted harmonic mean
      }
    }
  }

  /// Index i of the held sample: the largest i with t_i <= t (Side::right) or
  /// t_i < t (Side::left), clamped to 0 when there is none.
  Eigen::Index locate(double t, Side side, SignalCursor& cursor) const {
    const Eigen::Index n = times_.size();
    const double* ts = times_.data();
    // "t_i is at or before t" for the requested side.
    auto at_or_before = [side, t](double ti) { return side == Side::right ? ti <= t : ti < t; };
    if (!(at_or_before(ts[0]))) return cursor.index = 0;  // before the range (or NaN)
    Eigen::Index i = std::clamp<Eigen::Index>(cursor.index, 0, n - 1);
    // Walk a few samples from the cursor: O(1) for monotone, dense queries.
    constexpr int k_walk = 4;
    if (at_or_before(ts[i])) {
      for (int w = 0; w < k_walk; ++w) {
        if (i + 1 >= n || !at_or_before(ts[i + 1])) return cursor.index = i;
        ++i;
      }
      // Binary search in (i, n): first index whose time is not at_or_before.
      const double* first = ts + i + 1;
      const double* last = ts + n;
      const double* it =
          side == Side::right ? std::upper_bound(first, last, t) : std::lower_bound(first, last, t);
      return cursor.index = static_cast<Eigen::Index>(it - ts) - 1;
    }
    for (int w = 0; w < k_walk && i > 0; ++w) {
      --i;
      if (at_or_before(ts[i])) return cursor.index = i;
    }
    // ts[0] is at_or_before and ts[i] is not: search in [0, i).
    const double* it =
        side == Side::right ? std::upper_bound(ts, ts + i, t) : std::lower_bound(ts, ts + i, t);
    return cursor.index = static_cast<Eigen::Index>(it - ts) - 1;
  }

  Eigen::VectorXd times_;
  Eigen::MatrixXd samples_;  // P x N: sample i is the contiguous column i
  Eigen::MatrixXd slopes_;   // P x N, PCHIP only: du/dt at each sample
  Interpolation interpolation_ = Interpolation::zero_order_hold;
  SignalCursor cursor_;
};

}  // namespace softrne::signals
