#pragma once
/// \file
/// \brief Plain description of a robot as `robot.json` (format `softrne-robot/1`,
/// docs/formats.md section 1) holds it: no JSON, no dynamics.

#include <cmath>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

namespace softrne::io {

/// \brief A constant-curvature pneumatic continuum joint (two coordinates u, v).
struct CCJointSpec {
  std::string name;  ///< unique among the segments
  double mass = 0.0;                                    ///< kg, spread uniformly along the arc
  double height = 0.0;                                  ///< m, arc length
  double diameter = 0.0;                                ///< m, of the thin disks
  double chamber_distance = 0.0;                        ///< m, d in eq. 24
  double chamber_radius = 0.0;                          ///< m, r in A = pi r^2 (eq. 24)
  Eigen::Vector2d stiffness = Eigen::Vector2d::Zero();  ///< N m/rad, diagonal K_spring for (u, v)
  Eigen::Vector2d damping = Eigen::Vector2d::Zero();    ///< N m s/rad, diagonal K_d for (u, v)

  /// \brief Torque per chamber pressure, rows (u, v), one column per chamber (m^3):
  /// \f$\tau = P p\f$. Always filled: eq. 24, \f$[[dA,-dA,0,0],[0,0,dA,-dA]]\f$,
  /// unless the file gives `pressure_to_torque` (then `custom_pressure_map`).
  Eigen::Matrix<double, 2, Eigen::Dynamic> pressure_to_torque;
  bool custom_pressure_map = false;      ///< true if `pressure_to_torque` came from the file
  std::string inertia_model = "lumped";  ///< "lumped" | "distributed"
  int quadrature_points = 0;             ///< 0 = the simulator's default
};

/// \brief A rigid body fixed to the previous segment's distal frame.
struct RigidLinkSpec {
  std::string name;  ///< unique among the segments
  double mass = 0.0;    ///< kg
  double length = 0.0;  ///< m, the distal frame is translated by [0, 0, length]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();          ///< m, in the base frame of the link
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Identity();  ///< kg m^2, about the COM, in that frame
};

/// \brief A massless revolute joint about a unit `axis` of its base frame.
struct RevoluteJointSpec {
  std::string name;  ///< unique among the segments
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  ///< unit, in its base frame
  double stiffness = 0.0;  ///< N m/rad
  double damping = 0.0;    ///< N m s/rad
};

/// \brief One segment of the chain, base to tip.
using SegmentSpec = std::variant<CCJointSpec, RigidLinkSpec, RevoluteJointSpec>;

/// \brief An effect that a fit added to the declared model (formats.md section 4).
struct EffectSpec {
  std::string name;  ///< the effect's name (softrne::effect_names())
  std::vector<std::string> joints;  ///< names of segments it applies to

  /// By name: `<kind>` (shared) or `<kind>.<joint, coordinate or pressure channel>`; the
  /// names present set the scope (formats.md section 4, read by softrne::build_arm).
  std::map<std::string, double> params;
  std::string evidence;  ///< short human-readable reason
};

/// \brief A motion-capture marker: a point fixed in a segment's distal frame (issue 19).
/// Data files carry its measured position as `<name>_x`, `<name>_y`, `<name>_z` in m, in
/// the motion-capture frame (formats.md sections 1 and 2).
struct MarkerSpec {
  std::string name;     ///< its name (letters, digits, '_'; starts with a letter)
  std::string segment;  ///< the segment whose distal frame carries it
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< in that frame, m
};

/// \brief A whole robot: `robot.json`.
struct RobotSpec {
  std::string name;  ///< the robot's name
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< m/s^2, in the base frame
  std::vector<SegmentSpec> segments;  ///< base to tip
  std::vector<EffectSpec> effects;    ///< effects added by a fit (empty when declared)
  std::vector<MarkerSpec> markers;    ///< motion-capture markers (may be empty)
  std::string source;  ///< the file it was read from, for messages
};

/// \brief Paper eq. 24: \f$\tau_u = dA(p_0 - p_1)\f$, \f$\tau_v = dA(p_2 - p_3)\f$,
/// \f$A = \pi r^2\f$, as a 2 x 4 matrix.
/// \param[in] chamber_distance d, from the joint's axis to a chamber's centre, m.
/// \param[in] chamber_radius r, a chamber's radius (the paper's delta, A = pi delta^2), m.
/// \return K_prs, m^3 (N m per Pa).
inline Eigen::Matrix<double, 2, Eigen::Dynamic> default_pressure_to_torque(double chamber_distance,
                                                                           double chamber_radius) {
  const double pi = 3.14159265358979323846;
  const double dA = chamber_distance * pi * chamber_radius * chamber_radius;
  Eigen::Matrix<double, 2, Eigen::Dynamic> m(2, 4);
  m << dA, -dA, 0.0, 0.0,  //
      0.0, 0.0, dA, -dA;
  return m;
}

/// \brief A cc joint with the eq. 24 pressure map filled in.
/// \param[in] name Its name.
/// \param[in] mass kg.
/// \param[in] height Arc length, m.
/// \param[in] diameter Of the thin disks, m.
/// \param[in] chamber_distance d of eq. 24, m.
/// \param[in] chamber_radius r of eq. 24, m.
/// \param[in] stiffness Diagonal of K_spring, N m/rad.
/// \param[in] damping Diagonal of K_d, N m s/rad.
/// \return The joint's description.
inline CCJointSpec make_cc_joint(std::string name, double mass, double height, double diameter,
                                 double chamber_distance, double chamber_radius,
                                 const Eigen::Vector2d& stiffness, const Eigen::Vector2d& damping) {
  CCJointSpec j;
  j.name = std::move(name);
  j.mass = mass;
  j.height = height;
  j.diameter = diameter;
  j.chamber_distance = chamber_distance;
  j.chamber_radius = chamber_radius;
  j.stiffness = stiffness;
  j.damping = damping;
  j.pressure_to_torque = default_pressure_to_torque(chamber_distance, chamber_radius);
  return j;
}

/// \brief Inertia matrix from `[ixx, iyy, izz, ixy, ixz, iyz]` (the matrix
/// entries, as in URDF: \f$I = [[i_{xx}, i_{xy}, i_{xz}], [i_{xy}, i_{yy}, i_{yz}], [i_{xz},
/// i_{yz}, i_{zz}]]\f$).
/// \param[in] ixx Entry (0, 0), kg m^2.
/// \param[in] iyy Entry (1, 1).
/// \param[in] izz Entry (2, 2).
/// \param[in] ixy Entries (0, 1) and (1, 0).
/// \param[in] ixz Entries (0, 2) and (2, 0).
/// \param[in] iyz Entries (1, 2) and (2, 1).
/// \return The symmetric matrix.
inline Eigen::Matrix3d inertia_from_array(double ixx, double iyy, double izz, double ixy,
                                          double ixz, double iyz) {
  Eigen::Matrix3d I;
  I << ixx, ixy, ixz,  //
      ixy, iyy, iyz,   //
      ixz, iyz, izz;
  return I;
}

/// \brief `[ixx, iyy, izz, ixy, ixz, iyz]` of an inertia matrix (the upper triangle).
/// \param[in] I An inertia matrix.
/// \return Its six entries, in the order of inertia_from_array().
inline Eigen::Matrix<double, 6, 1> inertia_to_array(const Eigen::Matrix3d& I) {
  Eigen::Matrix<double, 6, 1> a;
  a << I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2);
  return a;
}

/// \brief "cc_joint", "rigid_link" or "revolute_joint".
/// \param[in] s A segment.
/// \return Its `type` in robot files.
inline const char* segment_type(const SegmentSpec& s) {
  switch (s.index()) {
    case 0:
      return "cc_joint";
    case 1:
      return "rigid_link";
    default:
      return "revolute_joint";
  }
}

/// \brief The segment's name.
/// \param[in] s A segment.
/// \return Its name.
inline const std::string& segment_name(const SegmentSpec& s) {
  return std::visit([](const auto& x) -> const std::string& { return x.name; }, s);
}

/// \brief Number of coordinates of a segment: 2, 0 or 1.
/// \param[in] s A segment.
/// \return 2 (cc joint), 0 (rigid link) or 1 (revolute joint).
inline int segment_nq(const SegmentSpec& s) {
  switch (s.index()) {
    case 0:
      return 2;
    case 1:
      return 0;
    default:
      return 1;
  }
}

/// \brief Number of cc joints.
/// \param[in] r A robot.
/// \return How many of its segments are cc joints.
inline std::size_t num_cc_joints(const RobotSpec& r) {
  std::size_t n = 0;
  for (const auto& s : r.segments) n += std::holds_alternative<CCJointSpec>(s) ? 1u : 0u;
  return n;
}

/// \brief Number of coordinates (2 per cc joint, 1 per revolute joint).
/// \param[in] r A robot.
/// \return nq.
inline std::size_t num_coordinates(const RobotSpec& r) {
  std::size_t n = 0;
  for (const auto& s : r.segments) n += static_cast<std::size_t>(segment_nq(s));
  return n;
}

/// \brief Total number of pressure columns (sum of the chambers of the cc joints).
/// \param[in] r A robot.
/// \return The number of pressure inputs.
inline std::size_t num_pressure_columns(const RobotSpec& r) {
  std::size_t n = 0;
  for (const auto& s : r.segments)
    if (const auto* j = std::get_if<CCJointSpec>(&s))
      n += static_cast<std::size_t>(j->pressure_to_torque.cols());
  return n;
}

/// \brief Coordinate (angle column) names in chain order: `u{j}`, `v{j}` for the
/// j-th cc joint (1-based among cc joints), `q{name}` for a revolute joint.
/// \param[in] r A robot.
/// \return nq names.
inline std::vector<std::string> coordinate_names(const RobotSpec& r) {
  std::vector<std::string> names;
  std::size_t j = 0;
  for (const auto& s : r.segments) {
    if (std::holds_alternative<CCJointSpec>(s)) {
      ++j;
      names.push_back("u" + std::to_string(j));
      names.push_back("v" + std::to_string(j));
    } else if (const auto* rj = std::get_if<RevoluteJointSpec>(&s)) {
      names.push_back("q" + rj->name);
    }
  }
  return names;
}

/// \brief Pressure column names in robot order: `p{j}_{k}`, j = 1.. over cc
/// joints, k = 0..K_j-1.
/// \param[in] r A robot.
/// \return One name per pressure input.
inline std::vector<std::string> pressure_column_names(const RobotSpec& r) {
  std::vector<std::string> names;
  std::size_t j = 0;
  for (const auto& s : r.segments) {
    if (const auto* cc = std::get_if<CCJointSpec>(&s)) {
      ++j;
      for (Eigen::Index k = 0; k < cc->pressure_to_torque.cols(); ++k)
        names.push_back("p" + std::to_string(j) + "_" + std::to_string(k));
    }
  }
  return names;
}

}  // namespace softrne::io
