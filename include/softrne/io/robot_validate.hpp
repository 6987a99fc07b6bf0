#pragma once
/// \file
/// \brief Semantic checks of a RobotSpec (ranges, names, shapes), shared by the
/// JSON reader and writer and usable on a spec built in code.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <set>
#include <string>
#include <variant>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "softrne/io/errors.hpp"
#include "softrne/io/robot_spec.hpp"

namespace softrne::io {

/// \brief Largest `quadrature_points` accepted.
inline constexpr int kMaxQuadraturePoints = 100000;
/// \brief Tolerance on `|axis| - 1` for a revolute joint.
inline constexpr double kAxisUnitTolerance = 1e-6;

namespace detail {

/// \brief "<list>[<index>] '<name>'" (with an optional prefix such as "fitted_robot."; no
/// name part for an empty name): where an item of a list of the description is.
inline std::string item_where(const std::string& prefix, const char* list, std::size_t index,
                              const std::string& name) {
  std::string w = prefix + list + "[" + std::to_string(index) + "]";
  if (!name.empty()) w += " '" + one_line(name) + "'";
  return w;
}

/// \brief "segments[2] 'joint2'" (item_where()).
inline std::string segment_where(const std::string& prefix, std::size_t index,
                                 const std::string& name) {
  return item_where(prefix, "segments", index, name);
}

/// \brief "effects[0] 'stiffening'" (item_where()).
inline std::string effect_where(const std::string& prefix, std::size_t index,
                                const std::string& name) {
  return item_where(prefix, "effects", index, name);
}

/// \brief "markers[0] 'tip'" (item_where()).
inline std::string marker_where(const std::string& prefix, std::size_t index,
                                const std::string& name) {
  return item_where(prefix, "markers", index, name);
}

/// \brief Checks of one number of the description.
struct NumberCheck {
  const std::string& source;
  std::string where;  // "segments[0] 'joint1': field 'mass'"

  void finite(double v) const {
    if (!std::isfinite(v))
      throw InputError(Category::NonFinite, source, where,
                       "must be a finite number (got " + format_double(v) + ")");
  }
  void positive(double v) const {
    finite(v);
    if (!(v > 0.0))
      throw InputError(Category::OutOfRange, source, where,
                       "must be > 0 (got " + format_double(v) + ")");
  }
  void non_negative(double v) const {
    finite(v);
    if (!(v >= 0.0))
      throw InputError(Category::OutOfRange, source, where,
                       "must be >= 0 (got " + format_double(v) + ")");
  }
};

/// \brief A segment name is used in messages, effect references and (for a
/// revolute joint) in the CSV column `q<name>`: non-empty, no comma, quote or
/// control character, no leading or trailing space.
inline void validate_segment_name(const std::string& name, const std::string& source,
                                  const std::string& where) {
  const std::string fw = field_where(where, "name");
  if (name.empty()) throw InputError(Category::InvalidValue, source, fw, "must not be empty");
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == ',' || c == '"' || c < 0x20 || c == 0x7f)
      throw InputError(
          Category::InvalidValue, source, fw,
          "must not contain commas, quotes or control characters (got " + quoted(name) + ")");
  }
  if (name.front() == ' ' || name.back() == ' ')
    throw InputError(Category::InvalidValue, source, fw,
                     "must not start or end with a space (got " + quoted(name) + ")");
}

inline void validate_cc_joint(const CCJointSpec& j, const std::string& source,
                              const std::string& where) {
  NumberCheck{source, field_where(where, "mass")}.positive(j.mass);
  NumberCheck{source, field_where(where, "height")}.positive(j.height);
  NumberCheck{source, field_where(where, "diameter")}.positive(j.diameter);
  NumberCheck{source, field_where(where, "chamber_distance")}.positive(j.chamber_distance);
  NumberCheck{source, field_where(where, "chamber_radius")}.positive(j.chamber_radius);
  for (int i = 0; i < 2; ++i) {
    NumberCheck{source, field_where(where, "stiffness[" + std::to_string(i) + "]")}.non_negative(
        j.stiffness[i]);
    NumberCheck{source, field_where(where, "damping[" + std::to_string(i) + "]")}.non_negative(
        j.damping[i]);
  }
  const auto& P = j.pressure_to_torque;
  if (P.cols() < 1)
    throw InputError(Category::BadShape, source, field_where(where, "pressure_to_torque"),
                     "must be 2 x K with K >= 1 (got 2 x 0)");
  for (Eigen::Index r = 0; r < 2; ++r)
    for (Eigen::Index c = 0; c < P.cols(); ++c)
      NumberCheck{source, field_where(where, "pressure_to_torque[" + std::to_string(r) + "][" +
                                                 std::to_string(c) + "]")}
          .finite(P(r, c));
  if (j.inertia_model != "lumped" && j.inertia_model != "distributed")
    throw InputError(Category::InvalidValue, source, field_where(where, "inertia_model"),
                     "must be \"lumped\" or \"distributed\" (got " + quoted(j.inertia_model) + ")");
  if (j.quadrature_points < 0 || j.quadrature_points > kMaxQuadraturePoints)
    throw InputError(Category::OutOfRange, source, field_where(where, "quadrature_points"),
                     "must be in [0, " + std::to_string(kMaxQuadraturePoints) + "] (got " +
                         std::to_string(j.quadrature_points) + ")");
}

inline void validate_rigid_link(const RigidLinkSpec& l, const std::string& source,
                                const std::string& where) {
  NumberCheck{source, field_where(where, "mass")}.positive(l.mass);
  NumberCheck{source, field_where(where, "length")}.non_negative(l.length);
  for (int i = 0; i < 3; ++i)
    NumberCheck{source, field_where(where, "com[" + std::to_string(i) + "]")}.finite(l.com[i]);
  const std::string iw = field_where(where, "inertia");
  const auto a = inertia_to_array(l.inertia);
  for (int i = 0; i < 6; ++i)
    NumberCheck{source, field_where(where, "inertia[" + std::to_string(i) + "]")}.finite(a[i]);
  const double scale = l.inertia.cwiseAbs().maxCoeff();
  if ((l.inertia - l.inertia.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
    throw InputError(Category::InvalidValue, source, iw, "inertia matrix is not symmetric");
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(l.inertia, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d lam = eig.eigenvalues();  // ascending
  if (!(lam[0] > 0.0))
    throw InputError(Category::InvalidValue, source, iw,
                     "inertia matrix is not positive definite (principal moments " +
                         format_double(lam[0]) + ", " + format_double(lam[1]) + ", " +
                         format_double(lam[2]) + ")");
  const double tol = 1e-9 * lam.sum();
  if (lam[0] + lam[1] < lam[2] - tol)
    throw InputError(Category::InvalidValue, source, iw,
                     "principal moments violate the triangle inequality (" + format_double(lam[0]) +
                         " + " + format_double(lam[1]) + " < " + format_double(lam[2]) +
                         "): no physical body has them");
}

inline void validate_revolute_joint(const RevoluteJointSpec& r, const std::string& source,
                                    const std::string& where) {
  for (int i = 0; i < 3; ++i)
    NumberCheck{source, field_where(where, "axis[" + std::to_string(i) + "]")}.finite(r.axis[i]);
  const double n = r.axis.norm();
  if (!(std::abs(n - 1.0) <= kAxisUnitTolerance))
    throw InputError(Category::InvalidValue, source, field_where(where, "axis"),
                     "must be a unit vector (got length " + format_double(n) + ")");
  NumberCheck{source, field_where(where, "stiffness")}.non_negative(r.stiffness);
  NumberCheck{source, field_where(where, "damping")}.non_negative(r.damping);
}

/// \brief Checks of one segment on its own (not the names of the others).
inline void validate_segment(const SegmentSpec& s, std::size_t index, const std::string& source,
                             const std::string& prefix = "") {
  const std::string where = segment_where(prefix, index, segment_name(s));
  validate_segment_name(segment_name(s), source, where);
  if (const auto* j = std::get_if<CCJointSpec>(&s)) validate_cc_joint(*j, source, where);
  if (const auto* l = std::get_if<RigidLinkSpec>(&s)) validate_rigid_link(*l, source, where);
  if (const auto* r = std::get_if<RevoluteJointSpec>(&s))
    validate_revolute_joint(*r, source, where);
}

/// \brief Checks across segments: at least one, unique names, gravity, effects.
inline void validate_robot_global(const RobotSpec& robot, const std::string& source,
                                  const std::string& prefix = "") {
  for (int i = 0; i < 3; ++i)
    NumberCheck{source, prefix + "field 'gravity[" + std::to_string(i) + "]'"}.finite(
        robot.gravity[i]);
  if (robot.segments.empty())
    throw InputError(Category::Empty, source, prefix + "field 'segments'",
                     "must hold at least one segment");
  std::set<std::string> names;
  for (std::size_t i = 0; i < robot.segments.size(); ++i) {
    const std::string& name = segment_name(robot.segments[i]);
    if (!names.insert(name).second) {
      std::size_t first = 0;
      while (segment_name(robot.segments[first]) != name) ++first;
      throw InputError(Category::DuplicateName, source, segment_where(prefix, i, name),
                       "duplicate segment name (also segments[" + std::to_string(first) + "])");
    }
  }
  for (std::size_t e = 0; e < robot.effects.size(); ++e) {
    const EffectSpec& eff = robot.effects[e];
    const std::string where = effect_where(prefix, e, eff.name);
    if (eff.name.empty())
      throw InputError(Category::InvalidValue, source, field_where(where, "name"),
                       "must not be empty");
    for (std::size_t k = 0; k < eff.joints.size(); ++k)
      if (names.count(eff.joints[k]) == 0)
        throw InputError(Category::UnknownName, source,
                         field_where(where, "joints[" + std::to_string(k) + "]"),
                         "no segment is named " + quoted(eff.joints[k]));
    // Names are '<kind>' (shared) or '<kind>.<joint, coordinate or pressure channel>'
    // (formats.md section 4); which kinds and names an effect has is checked by build_arm.
    for (const auto& [key, value] : eff.params) {
      const std::size_t dot = key.find('.');
      if (key.empty() || dot == 0 || (dot != std::string::npos && dot + 1 == key.size()))
        throw InputError(Category::InvalidValue, source, field_where(where, "params." + key),
                         "a parameter name is '<kind>' or '<kind>.<joint, coordinate or "
                         "chamber>'");
      NumberCheck{source, field_where(where, "params." + key)}.finite(value);
    }
  }
  // Markers: a name that makes data columns <name>_x, _y, _z no other column has (not t,
  // p.._.., u.., v..), unique; a segment of the robot; a finite offset.
  std::set<std::string> marker_names;
  for (std::size_t k = 0; k < robot.markers.size(); ++k) {
    const MarkerSpec& m = robot.markers[k];
    const std::string where = marker_where(prefix, k, m.name);
    const bool identifier =
        !m.name.empty() && std::isalpha(static_cast<unsigned char>(m.name[0])) &&
        std::all_of(m.name.begin(), m.name.end(),
                    [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (!identifier)
      throw InputError(Category::InvalidValue, source, field_where(where, "name"),
                       "a marker name is a letter followed by letters, digits or '_' (its data "
                       "columns are <name>_x, <name>_y, <name>_z)");
    if (!marker_names.insert(m.name).second)
      throw InputError(Category::DuplicateName, source, field_where(where, "name"), "duplicate marker name");
    if (names.count(m.segment) == 0)
      throw InputError(Category::UnknownName, source, field_where(where, "segment"),
                       "no segment is named " + quoted(m.segment));
    for (int i = 0; i < 3; ++i)
      NumberCheck{source, field_where(where, "offset[" + std::to_string(i) + "]")}.finite(m.offset[i]);
  }
}

}  // namespace detail

/// \brief Check every rule of `softrne-robot/1` on a spec (built in code or read);
/// throws InputError naming `robot.source`, the segment and the field.
/// \param[in] robot The robot to check.
/// \throws InputError for the first rule it breaks.
inline void validate_robot(const RobotSpec& robot) {
  for (std::size_t i = 0; i < robot.segments.size(); ++i)
    detail::validate_segment(robot.segments[i], i, robot.source);
  detail::validate_robot_global(robot, robot.source);
}

}  // namespace softrne::io
