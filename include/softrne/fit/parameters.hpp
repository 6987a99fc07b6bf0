#pragma once
/// \file
/// \brief Named, bounded fit parameters and their map to the optimiser's
///        normalised coordinates.

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace softrne::fit {

/// \brief One scalar parameter of a fit, in physical units.
///
/// Invariants (checked by ParameterSet::add): `lower < upper`, both finite;
/// `lower > 0` when `log_scale`; `initial` is clamped into `[lower, upper]`.
struct Parameter {
  std::string name;      ///< unique within its ParameterSet
  double initial = 0.0;  ///< the starting value
  double lower = 0.0;    ///< the smallest allowed value
  double upper = 1.0;    ///< the largest allowed value

  /// Search in \f$\log x\f$ (for positive quantities spanning decades).
  bool log_scale = false;
};

/// \brief An ordered set of parameters and the map between physical values
///        \f$x\f$ and normalised coordinates \f$u \in [0,1]^p\f$.
///
/// \f$u_i = (x_i - l_i)/(h_i - l_i)\f$, or
/// \f$u_i = (\log x_i - \log l_i)/(\log h_i - \log l_i)\f$ when log-scaled.
/// The optimisers work in \f$u\f$, so every parameter has a unit box and
/// finite-difference steps and tolerances mean the same for all of them.
class ParameterSet {
 public:
  ParameterSet() = default;

  /// \brief Validates and adds each parameter (see add()).
  /// \param[in] parameters The parameters, in order.
  /// \throws std::invalid_argument as add().
  explicit ParameterSet(const std::vector<Parameter>& parameters) {
    for (const Parameter& p : parameters) add(p);
  }

  /// \brief Validates and appends a parameter; returns its index.
  /// \param[in] p The parameter.
  /// \return Its index.
  /// \throws std::invalid_argument on an empty or duplicate name, non-finite
  ///         values, `lower >= upper`, or `lower <= 0` with `log_scale`.
  ///         An `initial` outside the bounds is clamped and a note recorded.
  int add(Parameter p) {
    if (p.name.empty()) throw std::invalid_argument("softrne::fit: parameter with an empty name");
    if (index_of(p.name) >= 0)
      throw std::invalid_argument("softrne::fit: duplicate parameter name '" + p.name + "'");
    if (!std::isfinite(p.lower) || !std::isfinite(p.upper) || !std::isfinite(p.initial))
      throw std::invalid_argument("softrne::fit: parameter '" + p.name +
                                  "' has a non-finite value");
    if (!(p.lower < p.upper))
      throw std::invalid_argument("softrne::fit: parameter '" + p.name + "' needs lower < upper");
    if (p.log_scale && !(p.lower > 0.0))
      throw std::invalid_argument("softrne::fit: log-scaled parameter '" + p.name +
                                  "' needs lower > 0");
    if (p.initial < p.lower || p.initial > p.upper) {
      const double clamped = std::clamp(p.initial, p.lower, p.upper);
      std::ostringstream note;
      note << "parameter '" << p.name << "': initial value " << p.initial << " outside [" << p.lower
           << ", " << p.upper << "], clamped to " << clamped;
      notes_.push_back(note.str());
      p.initial = clamped;
    }
    parameters_.push_back(std::move(p));
    return static_cast<int>(parameters_.size()) - 1;
  }

  /// \return The number of parameters \f$p\f$.
  int size() const { return static_cast<int>(parameters_.size()); }
  /// \param[in] i An index, 0 <= i < size().
  /// \return Parameter i.
  /// \throws std::out_of_range if i is out of range.
  const Parameter& operator[](int i) const { return parameters_.at(static_cast<std::size_t>(i)); }
  /// \return All parameters, in order.
  const std::vector<Parameter>& parameters() const { return parameters_; }
  /// \return Notes written during validation (clamped initial values).
  const std::vector<std::string>& notes() const { return notes_; }

  /// \brief Index of the parameter called `name`, or -1.
  /// \param[in] name A parameter name.
  /// \return Its index, or -1.
  int index_of(const std::string& name) const {
    for (std::size_t i = 0; i < parameters_.size(); ++i)
      if (parameters_[i].name == name) return static_cast<int>(i);
    return -1;
  }

  /// \return The initial values, in order.
  Eigen::VectorXd initial() const { return collect(&Parameter::initial); }
  /// \return The lower bounds, in order.
  Eigen::VectorXd lower() const { return collect(&Parameter::lower); }
  /// \return The upper bounds, in order.
  Eigen::VectorXd upper() const { return collect(&Parameter::upper); }

  /// \brief \f$u_i(x_i)\f$; values outside the bounds are clamped first.
  /// \param[in] i A parameter index.
  /// \param[in] x A physical value.
  /// \return Its normalised coordinate in [0, 1].
  double to_normalised(int i, double x) const {
    const Parameter& p = (*this)[i];
    x = std::clamp(x, p.lower, p.upper);
    const double u =
        p.log_scale ? (std::log(x) - std::log(p.lower)) / (std::log(p.upper) - std::log(p.lower))
                    : (x - p.lower) / (p.upper - p.lower);
    return std::clamp(u, 0.0, 1.0);
  }

  /// \brief \f$x_i(u_i)\f$; `u` is clamped into [0, 1] and the result into the bounds.
  /// \param[in] i A parameter index.
  /// \param[in] u A normalised coordinate.
  /// \return The physical value.
  double to_physical(int i, double u) const {
    const Parameter& p = (*this)[i];
    u = std::clamp(u, 0.0, 1.0);
    const double x = p.log_scale
                         ? std::exp(std::log(p.lower) + u * (std::log(p.upper) - std::log(p.lower)))
                         : p.lower + u * (p.upper - p.lower);
    return std::clamp(x, p.lower, p.upper);
  }

  /// \brief Element-wise to_normalised().
  /// \param[in] x The physical values (size()).
  /// \return The normalised coordinates.
  /// \throws std::invalid_argument if x has another size.
  Eigen::VectorXd to_normalised(const Eigen::VectorXd& x) const {
    check_size(x);
    Eigen::VectorXd u(size());
    for (int i = 0; i < size(); ++i) u[i] = to_normalised(i, x[i]);
    return u;
  }

  /// \brief Element-wise to_physical().
  /// \param[in] u The normalised coordinates (size()).
  /// \return The physical values.
  /// \throws std::invalid_argument if u has another size.
  Eigen::VectorXd to_physical(const Eigen::VectorXd& u) const {
    check_size(u);
    Eigen::VectorXd x(size());
    for (int i = 0; i < size(); ++i) x[i] = to_physical(i, u[i]);
    return x;
  }

  /// \brief \f$dx_i/du_i\f$ at physical value `x` (chain rule for Jacobians).
  /// \param[in] i A parameter index.
  /// \param[in] x A physical value.
  /// \return The derivative.
  double dphysical_dnormalised(int i, double x) const {
    const Parameter& p = (*this)[i];
    return p.log_scale ? x * (std::log(p.upper) - std::log(p.lower)) : (p.upper - p.lower);
  }

 private:
  Eigen::VectorXd collect(double Parameter::*member) const {
    Eigen::VectorXd v(size());
    for (int i = 0; i < size(); ++i) v[i] = parameters_[static_cast<std::size_t>(i)].*member;
    return v;
  }
  void check_size(const Eigen::VectorXd& v) const {
    if (v.size() != size())
      throw std::invalid_argument("softrne::fit: vector size does not match the parameter set");
  }

  std::vector<Parameter> parameters_;
  std::vector<std::string> notes_;
};

}  // namespace softrne::fit
