#pragma once
/// \file
/// \brief An independent generator of random soft arms with injected effects, for judging the
/// closed loop (softrne::fit::run_loop) on arms, effects and values nobody tuned it to.
///
/// A case is
/// - the TRUE robot: random geometry, every CC joint with `inertia_model = "distributed"` (so
///   the data comes from another code path than the lumped model that is fitted), plus the
///   injected effects as robot-file entries (io::EffectSpec, built by build_arm: the effects
///   go through the same path as a user's robot.json, their physics is not re-coded here);
/// - the DECLARED robot: the same segments with the lumped inertia, no effects, and every
///   stiffness and damping entry off by its own log-uniform factor in [1/1.5, 1.5];
/// - train data (random pressure steps) and test data (smooth inputs), 100 Hz, simulated
///   through the true description with rtol 1e-8 / atol 1e-9, plus sensor noise
///   N(0, 0.003 rad) on angles and N(0, 300 Pa) on the recorded pressures.
///
/// Arm distribution (stream "arm" of the seed; the arm does not depend on the effects asked
/// for, so a seed gives the same arm for a control and for every effect):
/// - 1 to 4 CC joints, 4 chambers each (eq. 24): mass U[0.2, 1.2] kg, height U[0.10, 0.25] m,
///   diameter = height x U[0.8, 1.2], chamber distance = diameter x U[0.22, 0.35], chamber
///   radius = diameter x U[0.08, 0.14];
/// - after each CC joint a rigid link with probability 0.6 (a solid rod: length U[0.03, 0.2] m,
///   radius U[0.015, 0.05] m, mass U[0.1, 1.5] kg (upright arms: U[0.1, 0.6] kg), com at
///   mid-length, rod inertia
///   m(3r^2 + l^2)/12, m r^2/2);
/// - with probability 0.3 one passive revolute joint (axis z = twist, or x or y = a hinge)
///   before a segment that carries mass; spring from a natural frequency U[0.8, 2.5] Hz of the
///   inertia it moves, damping ratio U[0.1, 0.4];
/// - mounting, 1/3 each: hanging (gravity +z in the base frame, as arm-a-1), wall (gravity
///   perpendicular to the base axis, random direction in the x-y plane), upright (gravity -z).
///
/// Stiffness, pressures and stability (see design_arm):
/// - each joint gets a design angle theta U[0.3, 0.8] rad and a pressure range pmax
///   U[80, 150] kPa; the spring is K = dA pmax / theta x U[0.85, 1.15] (per axis) minus the
///   gravity stiffness dG/dq at q = 0 (hanging: gravity helps; upright: it destabilises);
/// - wall-mounted: K >= 2.5 L (L = the joint's gravity moment with the arm straight and
///   horizontal), so the sag under its own weight stays below ~0.4 rad per joint;
/// - every arm: K >= 0.25 dA pmax / theta (gravity never does most of the holding);
/// - stability margin: with 1.6 times every mass and a tip mass equal to the last joint's
///   distal mass (covering mass_scale and payload), the smallest eigenvalue of
///   K^-1/2 (K + dG/dq) K^-1/2 must be >= 0.5 (gravity takes at most half of the stiffness):
///   otherwise the springs that the softest mode bends are raised (up to 50 %) until it is;
/// - then pmax is calibrated on the nonlinear equilibrium of the true (distributed) arm so that
///   one chamber at pmax bends its joint by theta (three passes); where that would need more
///   than 150 kPa or less than 60 kPa the chambers grow or shrink instead (radius 0.06-0.16,
///   distance 0.2-0.36 of the diameter), and pmax is clamped to [30, 200] kPa;
/// - damping: D = 2 zeta sqrt(K_eff M_ii), zeta U[0.15, 0.5];
/// - a drawn arm whose simulation fails or bends beyond 1.6 rad is redrawn (attempt + 1).
///
/// Effect strengths: each effect has a severity x (documented per effect in effect_table(),
/// relative to the arm's own scales: stiffness, pressure torque, speed) drawn in [x_lo, x_hi]
/// and then calibrated: the effect alone is simulated against the effect-free truth on the
/// train inputs, and x is multiplied by 1.6 while the largest per-coordinate RMS change of the
/// angles is below 4 x the angle noise (0.012 rad), or divided by 1.6 while it is above
/// 0.25 rad, within hard caps [x_min, x_max]. None of this reads the library's fit bounds.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "softrne/algorithms/bias.hpp"
#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/arm/equilibrium.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_spec.hpp"
#include "softrne/sim/arm_simulation.hpp"

namespace softrne::gen {

// ---- random numbers: portable (mt19937_64's sequence is fixed by the standard; the
// distributions are our own, so every platform gives the same case for a seed) -------------

class Rng {
 public:
  Rng(std::uint64_t seed, const std::string& stream) : eng_(mix(seed, stream)) {}
  double uniform() { return static_cast<double>(eng_() >> 11) * 0x1.0p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double log_uniform(double a, double b) { return std::exp(uniform(std::log(a), std::log(b))); }
  /// Integer in [lo, hi].
  int integer(int lo, int hi) {
    const int k = lo + static_cast<int>(uniform() * (hi - lo + 1));
    return std::min(k, hi);
  }
  bool chance(double p) { return uniform() < p; }
  double sign() { return chance(0.5) ? 1.0 : -1.0; }
  double normal() {  // Box-Muller
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0) u1 = uniform();
    const double u2 = uniform(), r = std::sqrt(-2 * std::log(u1)), a = 6.283185307179586 * u2;
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  static std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  static std::uint64_t mix(std::uint64_t seed, const std::string& s) {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the stream name
    for (char c : s) {
      h ^= static_cast<unsigned char>(c);
      h *= 1099511628211ull;
    }
    std::uint64_t x = seed ^ (h * 0x9E3779B97F4A7C15ull);
    splitmix(x);
    return splitmix(x);
  }
  std::mt19937_64 eng_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// ---- the table of effects --------------------------------------------------------------

/// \brief One effect the generator can inject.
struct EffectInfo {
  std::string name;
  std::vector<std::string> kinds;   ///< parameter kinds ("beta"; "k", "tau" for viscoelastic)
  std::vector<std::string> scopes;  ///< allowed: shared, joint, coordinate, chamber
  bool legacy;                      ///< one of the eight effects of the first loop
  double x_lo, x_hi;                ///< severity drawn in [x_lo, x_hi]
  double x_min, x_max;              ///< hard caps of the calibration
  std::string rule;                 ///< how the severity x becomes parameters
};

/// \brief All fourteen effects. Severity x and the rule that turns it into parameters; the
/// per-joint scales are those of the generated arm (design angle theta, pressure range pmax,
/// pressure torque tau_max = dA pmax, springs K, dampers D, the 90th percentile v90 of the
/// joint's speed in the effect-free train run, the distal mass m_tip of the last CC joint).
/// "Shared" means one value for all CC joints (joint scales then averaged geometrically).
inline const std::vector<EffectInfo>& effect_table() {
  static const std::vector<EffectInfo> t = {
      {"stiffening", {"beta"}, {"shared", "joint"}, true, 0.3, 1.0, 0.15, 2.0,
       "beta = x / theta^2: the spring is 30-100 % stiffer at the design angle"},
      {"pressure_stiffening", {"gamma"}, {"shared", "joint"}, true, 0.3, 0.8, 0.15, 1.5,
       "gamma = x / (2 pmax [MPa]): 30-80 % stiffer at the mean summed pressure 2 pmax"},
      {"actuator_lag", {"T"}, {"shared", "joint"}, true, 0.04, 0.15, 0.02, 0.3,
       "T = x s (valve and tube time constant 40-150 ms)"},
      {"coulomb_friction", {"Fc"}, {"shared", "joint", "coordinate"}, true, 0.03, 0.08, 0.015,
       0.15, "Fc = x tau_max: dead band x theta (3-8 % of the pressure torque)"},
      {"quadratic_damping", {"c2"}, {"shared", "joint", "coordinate"}, true, 0.5, 2.0, 0.25, 5.0,
       "c2 = x D / v90: the drag equals x times the linear damping at the 90th-percentile speed"},
      {"chamber_misalignment", {"psi"}, {"shared", "joint"}, true, 0.15, 0.4, 0.08, 0.7,
       "psi = +-x rad (9-23 degrees)"},
      {"payload", {"mass"}, {"shared"}, true, 0.3, 0.8, 0.15, 1.0,
       "mass = x m_tip (30-80 % of the mass beyond the last CC joint's base)"},
      {"angle_offset", {"offset"}, {"coordinate"}, true, 0.02, 0.05, 0.012, 0.1,
       "offset = +-x U[0.6, 1] rad per coordinate of one joint"},
      {"viscoelastic", {"k", "tau"}, {"shared", "joint"}, false, 0.3, 0.8, 0.15, 1.5,
       "k = x mean(K) N m/rad, tau = U[0.2, 1.0] s (a relaxing spring, 30-80 % of K)"},
      {"chamber_gain", {"gain"}, {"chamber", "joint"}, false, 0.4, 0.8, 0.1, 0.85,
       "chamber: one weak chamber at gain 1 - x (0.2-0.6), the joint's others at 1; joint: "
       "gain 1 - x/2 for all its chambers"},
      {"input_delay", {"delay"}, {"shared"}, false, 0.03, 0.12, 0.015, 0.25,
       "delay = x s (30-120 ms)"},
      {"hysteresis", {"Fmax", "sigma"}, {"shared", "joint"}, false, 0.04, 0.1, 0.02, 0.2,
       "Fmax = x tau_max, sigma = Fmax / U[0.02, 0.08] rad (saturates over a few hundredths "
       "of a radian)"},
      {"mass_scale", {"scale"}, {"shared", "joint"}, false, 0.3, 0.6, 0.15, 0.6,
       "scale = 1 + x or 1 - x/2 (0.7-1.6; the stiffness design covers 1.6)"},
      {"sensor_gain", {"gain"}, {"shared", "joint", "coordinate"}, false, 0.1, 0.3, 0.05, 0.3,
       "gain = 1 +- x (0.7-0.9 or 1.1-1.3)"},
  };
  return t;
}

inline const EffectInfo* find_effect(const std::string& name) {
  for (const auto& e : effect_table())
    if (e.name == name) return &e;
  return nullptr;
}

// ---- cases ----------------------------------------------------------------------------

/// \brief An effect to inject; an empty scope is drawn from the effect's allowed scopes.
struct EffectRequest {
  std::string name;
  std::string scope;
};

struct CaseOptions {
  std::uint64_t seed = 1;
  std::vector<EffectRequest> effects;  ///< empty: an effect-free control
  double angle_noise = 0.003;          ///< rad, standard deviation
  double pressure_noise = 300;         ///< Pa, standard deviation
  double train_seconds = 10, test_seconds = 10;
  double hold_seconds = 1.0;  ///< zero pressure, at rest, at the start of each record
  double rate = 100;          ///< Hz
  bool calibrate = true;      ///< adjust effect strengths to the impact band
  int max_attempts = 5;
};

/// \brief What was injected, with the severity and the measured impact.
struct InjectedEffect {
  std::string name, scope;
  std::vector<std::string> joints;
  std::string target;  ///< the coordinate or pressure channel for those scopes
  std::map<std::string, double> params;
  double severity = 0;
  double impact = 0;  ///< largest per-coordinate RMS change of the train angles (rad)
  int calibration_steps = 0;
  std::string note;
  // drawn once, kept across calibration steps
  int cc = -1;     ///< index among the CC joints (joint, coordinate, chamber scopes)
  int axis = 0;    ///< coordinate 0 (u) or 1 (v)
  int chamber = 0;
  double sign = 1, aux = 0, aux2 = 0;
};

/// \brief The designed numbers of one CC joint.
struct JointDesign {
  std::string name;
  int segment = 0;
  double dA = 0;     ///< m^3, torque per Pa of one chamber
  double pmax = 0;   ///< Pa
  double theta = 0;  ///< rad, design angle at pmax
  double zeta = 0;
  double v90 = 0;  ///< rad/s, from the effect-free train run
  double mass = 0;
};

struct ArmDesign {
  std::string mounting;  ///< hanging | wall | upright
  std::string summary;   ///< e.g. "hanging C-L-R-C"
  std::vector<JointDesign> cc;
  double tip_mass = 0;          ///< kg beyond the base of the last CC joint
  double stability_margin = 0;  ///< lambda_min of K^-1/2 (K + dG/dq) K^-1/2, heavy arm
  int stiffness_raises = 0;
};

/// \brief Thrown when the library refuses an injected effect (e.g. a name it does not know
/// yet); `effect` names it.
class EffectBuildError : public std::runtime_error {
 public:
  EffectBuildError(std::string effect, const std::string& msg)
      : std::runtime_error(msg), effect(std::move(effect)) {}
  std::string effect;
};

struct Case {
  std::uint64_t seed = 0;
  int attempt = 0;
  io::RobotSpec truth, declared;
  io::Dataset train, test;
  std::vector<InjectedEffect> effects;
  ArmDesign design;
  double angle_noise = 0, pressure_noise = 0;
  Eigen::VectorXd q_rest;  ///< true coordinates at rest at the first sample
  double hold_drift = 0;   ///< largest |q(t) - q(0)| over the holds (clean, rad)
  double max_angle = 0;    ///< largest |angle| in both records (clean, rad)
  std::map<std::string, std::pair<Eigen::Vector2d, Eigen::Vector2d>> declared_factors;
};

namespace detail {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;

/// Builds, turning the library's refusal into EffectBuildError.
inline ArmDescription build(const io::RobotSpec& s) {
  try {
    return build_arm(s);
  } catch (const std::invalid_argument& e) {
    std::string eff;
    const std::string m = e.what();
    const auto a = m.find("effect '");
    if (a != std::string::npos) eff = m.substr(a + 8, m.find('\'', a + 8) - a - 8);
    throw EffectBuildError(eff, m);
  }
}

/// Static equilibrium at pressures p (softrne::static_equilibrium).
inline Vec equilibrium(const ArmDescription& d, const Vec& p, Vec q) { return static_equilibrium(d, p, std::move(q)); }

/// Measured first row whose initial state (the library's measurement model inverted) is q.
inline Vec measured_start(const ArmDescription& d, const Vec& q, const Vec& p0) {
  Vec m = q;
  for (int it = 0; it < 200; ++it) {
    const Vec back = initial_state(d, m, p0).head(d.nq);
    const Vec err = q - back;
    if (err.lpNorm<Eigen::Infinity>() < 1e-14) break;
    m += err;
  }
  return m;
}

struct SimOut {
  sim::ArmSimulation s;
  Vec q_rest;
};

/// Simulates from rest at the equilibrium of the first pressure row.
inline SimOut simulate_from_rest(const ArmDescription& d, const Vec& t, const Mat& p, bool tight,
                                 const Vec& guess = Vec()) {
  SimOut o;
  const Vec p0 = p.row(0).transpose();
  o.q_rest = equilibrium(d, p0, guess);
  sim::ArmSimulationOptions opt;
  opt.cvode.rtol = tight ? 1e-8 : 1e-6;
  opt.cvode.atol = tight ? 1e-9 : 1e-6;
  opt.cvode.max_steps = 2000000;
  o.s = sim::simulate_arm(d, t, p, measured_start(d, o.q_rest, p0), opt);
  return o;
}

inline double max_coordinate_rms(const Mat& a, const Mat& b) {
  if (a.rows() != b.rows() || a.rows() == 0) return HUGE_VAL;
  const Mat d = a - b;
  double m = 0;
  for (Eigen::Index k = 0; k < d.cols(); ++k)
    m = std::max(m, std::sqrt(d.col(k).squaredNorm() / static_cast<double>(d.rows())));
  return m;
}

inline double geomean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += std::log(x);
  return std::exp(s / static_cast<double>(v.size()));
}

inline io::RigidLinkSpec rod(const std::string& name, double m, double len, double radius) {
  io::RigidLinkSpec l;
  l.name = name;
  l.mass = m;
  l.length = len;
  l.com = Eigen::Vector3d(0, 0, len / 2);
  const double ixx = m * (3 * radius * radius + len * len) / 12;
  l.inertia = Eigen::Vector3d(ixx, ixx, m * radius * radius / 2).asDiagonal();
  return l;
}

/// The arm's gravity stiffness dG/dq at q = 0 (symmetrised) and mass matrix there.
inline void gravity_stiffness(const io::RobotSpec& s, Mat& Kg, Mat& M) {
  const ArmDescription d = build(s);
  auto chain = d.make_chain<double>();
  auto data = chain.make_data();
  const int n = d.nq;
  Kg.resize(n, n);
  Vec q = Vec::Zero(n);
  for (int k = 0; k < n; ++k) {
    Vec a = q, b = q;
    a(k) += 1e-6;
    b(k) -= 1e-6;
    const Vec ga = gravity(chain, data, a);
    const Vec gb = gravity(chain, data, b);
    Kg.col(k) = (ga - gb) / 2e-6;
  }
  Kg = 0.5 * (Kg + Kg.transpose()).eval();
  M = mass_matrix(chain, data, q);
}

/// The spec with every mass (and inertia) times `f` and a point mass `tip` at the tip.
inline io::RobotSpec heavier(io::RobotSpec s, double f, double tip) {
  for (auto& seg : s.segments) {
    if (auto* c = std::get_if<io::CCJointSpec>(&seg)) c->mass *= f;
    if (auto* l = std::get_if<io::RigidLinkSpec>(&seg)) {
      l->mass *= f;
      l->inertia *= f;
    }
  }
  if (tip > 0) {
    io::RigidLinkSpec p;
    p.name = "design_tip_mass";
    p.mass = tip;
    p.length = 0;
    p.inertia.setZero();
    s.segments.push_back(p);
  }
  return s;
}

/// Coordinate indices of each segment (-1 for a link).
inline std::vector<int> q_offsets(const io::RobotSpec& s) {
  std::vector<int> o;
  int q = 0;
  for (const auto& seg : s.segments) {
    o.push_back(io::segment_nq(seg) ? q : -1);
    q += io::segment_nq(seg);
  }
  return o;
}

/// Draws the arm (segments, mounting, stiffness, damping, pressure ranges): see the file
/// comment. Returns the effect-free true spec (distributed inertia).
inline io::RobotSpec design_arm(std::uint64_t seed, int attempt, ArmDesign& des) {
  Rng rng(seed, "arm/" + std::to_string(attempt));
  io::RobotSpec s;
  const int ncc = rng.integer(1, 4);
  const int mount = rng.integer(0, 2);
  const double g = 9.81;
  if (mount == 0) {
    des.mounting = "hanging";
    s.gravity = Eigen::Vector3d(0, 0, g);
  } else if (mount == 1) {
    des.mounting = "wall";
    const double phi = rng.uniform(0, 6.283185307179586);
    s.gravity = Eigen::Vector3d(g * std::cos(phi), g * std::sin(phi), 0);
  } else {
    des.mounting = "upright";
    s.gravity = Eigen::Vector3d(0, 0, -g);
  }
  int links = 0;
  for (int j = 1; j <= ncc; ++j) {
    const double h = rng.uniform(0.10, 0.25), m = rng.uniform(0.2, 1.2);
    const double dia = h * rng.uniform(0.8, 1.2);
    const double cd = dia * rng.uniform(0.22, 0.35), cr = dia * rng.uniform(0.08, 0.14);
    auto cc = io::make_cc_joint("joint" + std::to_string(j), m, h, dia, cd, cr,
                                Eigen::Vector2d(1, 1), Eigen::Vector2d(0.1, 0.1));
    cc.inertia_model = "distributed";
    s.segments.push_back(cc);
    if (rng.chance(0.6)) {
      const double len = rng.uniform(0.03, 0.2), rad = rng.uniform(0.015, 0.05);
      // Upright arms carry their links: lighter ones (0.1-0.6 kg), else 0.1-1.5 kg.
      const double lm = rng.uniform(0.1, des.mounting == "upright" ? 0.6 : 1.5);
      s.segments.push_back(rod("link" + std::to_string(++links), lm, len, rad));
    }
  }
  std::string rev_axis;
  if (rng.chance(0.3)) {
    const int pos = rng.integer(s.segments.size() > 1 ? 1 : 0, static_cast<int>(s.segments.size()) - 1);
    io::RevoluteJointSpec r;
    r.name = "rev1";
    const int ax = rng.integer(0, 3);  // z twice as likely: the twist joint of a wrist
    r.axis = ax == 0 ? Eigen::Vector3d::UnitX() : ax == 1 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
    rev_axis = ax == 0 ? "x" : ax == 1 ? "y" : "z";
    r.stiffness = 1;
    r.damping = 0.1;
    s.segments.insert(s.segments.begin() + pos, r);
  }
  s.name = "random arm (seed " + std::to_string(seed) + ")";
  des.summary = des.mounting + " ";
  for (std::size_t i = 0; i < s.segments.size(); ++i) {
    des.summary += (i ? "-" : "");
    des.summary += s.segments[i].index() == 0 ? "C" : s.segments[i].index() == 1 ? "L" : "R" + rev_axis;
  }

  // Straight-arm gravity moments L (the arm horizontal) and the distal masses.
  const auto qo = q_offsets(s);
  std::vector<double> zc(s.segments.size()), mass(s.segments.size(), 0.0), zbase(s.segments.size());
  double z = 0;
  for (std::size_t i = 0; i < s.segments.size(); ++i) {
    zbase[i] = z;
    if (const auto* c = std::get_if<io::CCJointSpec>(&s.segments[i])) {
      zc[i] = z + c->height / 2;
      mass[i] = c->mass;
      z += c->height;
    } else if (const auto* l = std::get_if<io::RigidLinkSpec>(&s.segments[i])) {
      zc[i] = z + l->com.z();
      mass[i] = l->mass;
      z += l->length;
    } else {
      zc[i] = z;
    }
  }
  auto moment = [&](std::size_t i) {
    double L = 0;
    for (std::size_t k = i; k < s.segments.size(); ++k) L += mass[k] * g * (zc[k] - zbase[i]);
    return L;
  };
  const int nq = static_cast<int>(io::num_coordinates(s));
  Vec K = Vec::Ones(nq), zeta(nq);
  Mat Kg, M;
  gravity_stiffness(s, Kg, M);
  for (std::size_t i = 0; i < s.segments.size(); ++i) {
    if (auto* c = std::get_if<io::CCJointSpec>(&s.segments[i])) {
      JointDesign jd;
      jd.name = c->name;
      jd.segment = static_cast<int>(i);
      jd.dA = c->pressure_to_torque(0, 0);
      jd.pmax = rng.uniform(80e3, 150e3);
      jd.theta = rng.uniform(0.3, 0.8);
      jd.zeta = rng.uniform(0.15, 0.5);
      jd.mass = c->mass;
      const double tmax = jd.dA * jd.pmax, L = moment(i);
      for (int a = 0; a < 2; ++a) {
        const int k = qo[i] + a;
        double kk = tmax / jd.theta * rng.uniform(0.85, 1.15) - Kg(k, k);
        kk = std::max(kk, 0.25 * tmax / jd.theta);
        if (des.mounting == "wall") kk = std::max(kk, 2.5 * L);
        K(k) = kk;
        zeta(k) = jd.zeta;
      }
      des.cc.push_back(jd);
    } else if (auto* r = std::get_if<io::RevoluteJointSpec>(&s.segments[i])) {
      const int k = qo[i];
      const double f = rng.uniform(0.8, 2.5), w = 6.283185307179586 * f;
      K(k) = std::max(M(k, k) * w * w - Kg(k, k), 0.05);
      if (des.mounting == "wall") K(k) = std::max(K(k), 2.5 * moment(i));
      zeta(k) = rng.uniform(0.1, 0.4);
      (void)r;
    }
  }
  // The distal mass of the last CC joint (payload scale).
  des.tip_mass = 0;
  for (std::size_t i = static_cast<std::size_t>(des.cc.back().segment); i < s.segments.size(); ++i)
    des.tip_mass += mass[i];

  // Stability margin on the heavy arm (masses x 1.6 plus a tip mass = tip_mass).
  Mat Kgh, Mh;
  gravity_stiffness(heavier(s, 1.6, des.tip_mass), Kgh, Mh);
  for (int it = 0; it < 60; ++it) {
    const Vec is = K.cwiseSqrt().cwiseInverse();
    const Mat S = is.asDiagonal() * (Mat(K.asDiagonal()) + Kgh) * is.asDiagonal();
    des.stability_margin = Eigen::SelfAdjointEigenSolver<Mat>(0.5 * (S + S.transpose())).eigenvalues()(0);
    if (des.stability_margin >= 0.5) break;
    // Raise the springs that the softest mode bends most (all by 25 % where it is global).
    Eigen::SelfAdjointEigenSolver<Mat> es(0.5 * (S + S.transpose()));
    const Vec v = es.eigenvectors().col(0).cwiseAbs2();
    for (int k = 0; k < nq; ++k) K(k) *= 1 + 0.5 * v(k) / v.maxCoeff();
    ++des.stiffness_raises;
  }
  auto apply = [&](const Vec& Kv, const Vec& Dv) {
    for (std::size_t i = 0; i < s.segments.size(); ++i) {
      if (auto* c = std::get_if<io::CCJointSpec>(&s.segments[i])) {
        c->stiffness = Kv.segment<2>(qo[i]);
        c->damping = Dv.segment<2>(qo[i]);
      } else if (auto* r = std::get_if<io::RevoluteJointSpec>(&s.segments[i])) {
        r->stiffness = Kv(qo[i]);
        r->damping = Dv(qo[i]);
      }
    }
  };
  Vec D(nq);
  for (int k = 0; k < nq; ++k) D(k) = 2 * zeta(k) * std::sqrt(std::max(K(k) + Kg(k, k), 0.2 * K(k)) * M(k, k));
  apply(K, D);

  // Pressure ranges: one chamber at pmax bends its joint by theta (nonlinear, true arm). Where
  // that needs more than 150 kPa (or less than 60 kPa) the chambers grow (shrink) instead,
  // within radius 0.06-0.16 and distance 0.2-0.36 of the diameter; pmax stays in [30, 200] kPa.
  const Vec q0 = equilibrium(build(s), Vec::Zero(static_cast<Eigen::Index>(4 * des.cc.size())), Vec::Zero(nq));
  for (int pass = 0; pass < 3; ++pass) {
    const ArmDescription d0 = build(s);
    for (std::size_t j = 0; j < des.cc.size(); ++j) {
      auto& jd = des.cc[j];
      auto& cs = std::get<io::CCJointSpec>(s.segments[static_cast<std::size_t>(jd.segment)]);
      const ArmJoint& aj = d0.joints[static_cast<std::size_t>(d0.joint_index(jd.name))];
      Vec p = Vec::Zero(d0.num_inputs);
      p(aj.input_offset) = jd.pmax;
      double bend = 0;
      try {
        const Vec q = equilibrium(d0, p, q0);
        bend = std::abs(q(aj.q_offset) - q0(aj.q_offset));
      } catch (const std::runtime_error&) {
        bend = 2 * jd.theta;  // no equilibrium: too much pressure
      }
      double ratio = std::clamp(jd.theta / std::max(bend, 1e-6), 0.25, 4.0);
      double pm = jd.pmax * ratio;
      if (pm > 150e3 || pm < 60e3) {
        const double want = pm / std::clamp(pm, 60e3, 150e3);  // the area factor wanted
        const double dia = cs.diameter;
        const double r = std::clamp(cs.chamber_radius * std::sqrt(want), 0.06 * dia, 0.16 * dia);
        const double left = want * std::pow(cs.chamber_radius / r, 2);
        const double dd = std::clamp(cs.chamber_distance * left, 0.2 * dia, 0.36 * dia);
        const double got = (dd * r * r) / (cs.chamber_distance * cs.chamber_radius * cs.chamber_radius);
        cs.chamber_radius = r;
        cs.chamber_distance = dd;
        cs.pressure_to_torque = io::default_pressure_to_torque(dd, r);
        jd.dA = cs.pressure_to_torque(0, 0);
        pm /= got;
      }
      jd.pmax = std::clamp(pm, 30e3, 200e3);
    }
  }
  return s;
}

inline Mat step_inputs(const Vec& t, const ArmDesign& des, double hold, Rng& rng) {
  Mat p = Mat::Zero(t.size(), static_cast<Eigen::Index>(4 * des.cc.size()));
  Vec target = Vec::Zero(p.cols()), value = Vec::Zero(p.cols());
  double next = hold;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    if (t(i) >= next) {
      for (Eigen::Index c = 0; c < p.cols(); ++c) target(c) = rng.uniform(0, des.cc[static_cast<std::size_t>(c / 4)].pmax);
      next += rng.uniform(0.5, 1.0);
    }
    const double dt = i > 0 ? t(i) - t(i - 1) : 0.0;
    value += (target - value) * (1 - std::exp(-dt / 0.03));  // 30 ms rise
    p.row(i) = value.transpose();
  }
  return p;
}

inline Mat smooth_inputs(const Vec& t, const ArmDesign& des, double hold, Rng& rng) {
  Mat p = Mat::Zero(t.size(), static_cast<Eigen::Index>(4 * des.cc.size()));
  for (Eigen::Index c = 0; c < p.cols(); ++c) {
    double f[3], ph[3], w[3], ws = 0;
    for (int k = 0; k < 3; ++k) {
      f[k] = rng.uniform(0.1, 1.0);
      ph[k] = rng.uniform(0, 6.283185307179586);
      w[k] = rng.uniform(0.3, 1.0);
      ws += w[k];
    }
    const double pmax = des.cc[static_cast<std::size_t>(c / 4)].pmax;
    for (Eigen::Index i = 0; i < t.size(); ++i) {
      const double tt = t(i) - hold;
      if (tt <= 0) continue;
      const double ramp = tt >= 1 ? 1.0 : 0.5 * (1 - std::cos(3.141592653589793 * tt));
      double s = 0;
      for (int k = 0; k < 3; ++k) s += w[k] * std::sin(6.283185307179586 * f[k] * tt + ph[k]);
      p(i, c) = pmax * ramp * (0.5 + 0.45 * s / ws);
    }
  }
  return p;
}

/// Parameters of an injected effect at severity x.
inline std::map<std::string, double> effect_params(const InjectedEffect& e, double x,
                                                   const io::RobotSpec& truth0, const ArmDesign& des,
                                                   const std::vector<std::string>& coords,
                                                   const std::vector<std::string>& pressures) {
  std::map<std::string, double> out;
  const bool shared = e.scope == "shared";
  std::vector<std::size_t> js;
  if (shared)
    for (std::size_t j = 0; j < des.cc.size(); ++j) js.push_back(j);
  else
    js.push_back(static_cast<std::size_t>(e.cc));
  auto K_of = [&](std::size_t j) {
    return std::get<io::CCJointSpec>(truth0.segments[static_cast<std::size_t>(des.cc[j].segment)]);
  };
  // Joint scale, geometric mean over js.
  auto scale = [&](auto fn) {
    std::vector<double> v;
    for (auto j : js) v.push_back(fn(j));
    return geomean(v);
  };
  // The key of a parameter kind for this scope.
  auto coord_of = [&]() {
    int q = 0;
    for (std::size_t i = 0; i < truth0.segments.size(); ++i) {
      if (static_cast<int>(i) == des.cc[static_cast<std::size_t>(e.cc)].segment) return coords[static_cast<std::size_t>(q + e.axis)];
      q += io::segment_nq(truth0.segments[i]);
    }
    return std::string();
  };
  auto key = [&](const std::string& kind) {
    if (shared) return kind;
    if (e.scope == "joint") return kind + "." + des.cc[static_cast<std::size_t>(e.cc)].name;
    if (e.scope == "coordinate") return kind + "." + coord_of();
    return kind + "." + pressures[static_cast<std::size_t>(4 * e.cc + e.chamber)];
  };
  const std::string& n = e.name;
  if (n == "stiffening") {
    out[key("beta")] = x / std::pow(scale([&](std::size_t j) { return des.cc[j].theta; }), 2);
  } else if (n == "pressure_stiffening") {
    out[key("gamma")] = x / (2e-6 * scale([&](std::size_t j) { return des.cc[j].pmax; }));
  } else if (n == "actuator_lag") {
    out[key("T")] = x;
  } else if (n == "coulomb_friction") {
    out[key("Fc")] = x * scale([&](std::size_t j) { return des.cc[j].dA * des.cc[j].pmax; });
  } else if (n == "quadratic_damping") {
    out[key("c2")] = x * scale([&](std::size_t j) {
      return K_of(j).damping.mean() / std::max(des.cc[j].v90, 0.05);
    });
  } else if (n == "chamber_misalignment") {
    out[key("psi")] = e.sign * x;
  } else if (n == "payload") {
    out["mass"] = x * des.tip_mass;
  } else if (n == "angle_offset") {
    // Both coordinates of the joint (the library wants every coordinate of a listed joint).
    const std::string u = coord_of();
    InjectedEffect other = e;
    other.axis = 1 - e.axis;
    std::string v;
    {
      int q = 0;
      for (std::size_t i = 0; i < truth0.segments.size(); ++i) {
        if (static_cast<int>(i) == des.cc[static_cast<std::size_t>(e.cc)].segment) v = coords[static_cast<std::size_t>(q + other.axis)];
        q += io::segment_nq(truth0.segments[i]);
      }
    }
    out["offset." + u] = e.sign * x;
    out["offset." + v] = (e.aux2 > 0 ? 1.0 : -1.0) * x * e.aux;
  } else if (n == "viscoelastic") {
    out[key("k")] = x * scale([&](std::size_t j) { return K_of(j).stiffness.mean(); });
    out[key("tau")] = e.aux;
  } else if (n == "chamber_gain") {
    if (e.scope == "chamber") {
      for (int c = 0; c < 4; ++c)
        out["gain." + pressures[static_cast<std::size_t>(4 * e.cc + c)]] = c == e.chamber ? 1 - x : 1.0;
    } else {
      out[key("gain")] = 1 - x / 2;
    }
  } else if (n == "input_delay") {
    out[key("delay")] = x;
  } else if (n == "hysteresis") {
    const double F = x * scale([&](std::size_t j) { return des.cc[j].dA * des.cc[j].pmax; });
    out[key("Fmax")] = F;
    out[key("sigma")] = F / e.aux;
  } else if (n == "mass_scale") {
    out[key("scale")] = e.sign > 0 ? 1 + x : 1 - x / 2;
  } else if (n == "sensor_gain") {
    out[key("gain")] = 1 + e.sign * x;
  }
  return out;
}

inline io::EffectSpec to_spec(const InjectedEffect& e) {
  io::EffectSpec s;
  s.name = e.name;
  s.joints = e.joints;
  s.params = e.params;
  s.evidence = "injected by softrne-make-case (" + e.scope + (e.target.empty() ? "" : " " + e.target) + ")";
  return s;
}

inline Vec time_grid(double seconds, double rate) {
  const int n = static_cast<int>(std::lround(seconds * rate));
  Vec t(n);
  for (int i = 0; i < n; ++i) t(i) = i / rate;
  return t;
}

inline io::Dataset noisy(const ArmDescription& d, const Vec& t, const Mat& p, const Mat& angles,
                         double an, double pn, Rng& rng, const std::string& source) {
  io::Dataset ds;
  ds.t = t;
  ds.pressures = p;
  ds.angles = angles;
  for (Eigen::Index i = 0; i < ds.angles.size(); ++i) ds.angles.data()[i] += an * rng.normal();
  for (Eigen::Index i = 0; i < ds.pressures.size(); ++i) ds.pressures.data()[i] += pn * rng.normal();
  ds.has_angles = true;
  ds.angle_names = d.coordinate_names;
  ds.pressure_names = d.pressure_names;
  ds.source = source;
  return ds;
}

}  // namespace detail

inline bool effect_builds(const std::string& name, const std::string& scope, std::string* why = nullptr);

/// \brief Makes one case (see the file comment). Throws std::invalid_argument on an unknown
/// effect or scope, EffectBuildError when the library refuses an injected effect, and
/// std::runtime_error when no stable arm was found in max_attempts draws.
inline Case make_case(const CaseOptions& opt) {
  using namespace detail;
  for (const auto& r : opt.effects) {
    const EffectInfo* info = find_effect(r.name);
    if (!info) throw std::invalid_argument("unknown effect '" + r.name + "'");
    if (!r.scope.empty() &&
        std::find(info->scopes.begin(), info->scopes.end(), r.scope) == info->scopes.end()) {
      std::string list;
      for (const auto& s : info->scopes) list += (list.empty() ? "" : ", ") + s;
      throw std::invalid_argument("effect '" + r.name + "': scope '" + r.scope +
                                  "' not meaningful (allowed: " + list + ")");
    }
  }
  for (std::size_t a = 0; a < opt.effects.size(); ++a)
    for (std::size_t b = a + 1; b < opt.effects.size(); ++b)
      if (opt.effects[a].name == opt.effects[b].name)
        throw std::invalid_argument("effect '" + opt.effects[a].name + "' given twice");

  std::string last_error;
  for (int attempt = 0; attempt < opt.max_attempts; ++attempt) {
    Case c;
    c.seed = opt.seed;
    c.attempt = attempt;
    c.angle_noise = opt.angle_noise;
    c.pressure_noise = opt.pressure_noise;
    io::RobotSpec truth0;
    try {
      truth0 = design_arm(opt.seed, attempt, c.design);
    } catch (const std::runtime_error& e) {
      last_error = std::string("arm design: ") + e.what();
      continue;
    }
    const ArmDescription d0 = build(truth0);
    const Vec t_train = time_grid(opt.train_seconds, opt.rate);
    const Vec t_test = time_grid(opt.test_seconds, opt.rate);
    Rng rin(opt.seed, "inputs/" + std::to_string(attempt));
    Rng rtest(opt.seed, "test-inputs/" + std::to_string(attempt));
    const Mat p_train = step_inputs(t_train, c.design, opt.hold_seconds, rin);
    const Mat p_test = smooth_inputs(t_test, c.design, opt.hold_seconds, rtest);

    // Effect-free reference on the train inputs (speeds for the rules, impact baseline).
    SimOut ref;
    try {
      ref = simulate_from_rest(d0, t_train, p_train, false);
    } catch (const std::runtime_error& e) {
      last_error = e.what();
      continue;
    }
    if (!ref.s.ok()) {
      last_error = "effect-free simulation: " + ref.s.result.message;
      continue;
    }
    {
      int q = 0, j = 0;
      for (const auto& seg : truth0.segments) {
        if (std::holds_alternative<io::CCJointSpec>(seg)) {
          std::vector<double> v;
          for (Eigen::Index i = 0; i < ref.s.states.rows(); ++i)
            v.push_back(std::max(std::abs(ref.s.states(i, d0.nq + q)), std::abs(ref.s.states(i, d0.nq + q + 1))));
          std::sort(v.begin(), v.end());
          c.design.cc[static_cast<std::size_t>(j++)].v90 = v[v.size() * 9 / 10];
        }
        q += io::segment_nq(seg);
      }
    }

    // Draw and calibrate each effect alone.
    bool failed = false;
    for (std::size_t k = 0; k < opt.effects.size() && !failed; ++k) {
      const auto& req = opt.effects[k];
      const EffectInfo& info = *find_effect(req.name);
      Rng re(opt.seed, "effect/" + req.name + "/" + std::to_string(attempt));
      InjectedEffect e;
      e.name = req.name;
      // A scope not asked for is drawn among those this build accepts (all if none does).
      std::vector<std::string> scopes;
      for (const auto& sc : info.scopes)
        if (req.scope.empty() && effect_builds(info.name, sc)) scopes.push_back(sc);
      if (scopes.empty()) scopes = info.scopes;
      const std::string drawn = scopes[static_cast<std::size_t>(re.integer(0, static_cast<int>(scopes.size()) - 1))];
      e.scope = req.scope.empty() ? drawn : req.scope;
      e.cc = re.integer(0, static_cast<int>(c.design.cc.size()) - 1);
      e.axis = re.integer(0, 1);
      e.chamber = re.integer(0, 3);
      e.sign = re.sign();
      if (e.name == "angle_offset") {
        e.aux = re.uniform(0.6, 1.0);
        e.aux2 = re.sign();
      } else if (e.name == "viscoelastic") {
        e.aux = re.uniform(0.2, 1.0);
      } else if (e.name == "hysteresis") {
        e.aux = re.uniform(0.02, 0.08);
      }
      if (e.name == "payload" || e.name == "input_delay") e.scope = "shared";
      if (e.scope == "shared") {
        for (const auto& jd : c.design.cc) e.joints.push_back(jd.name);
      } else {
        e.joints.push_back(c.design.cc[static_cast<std::size_t>(e.cc)].name);
      }
      if (e.name == "payload") e.joints.clear();
      double x = re.uniform(info.x_lo, info.x_hi);
      auto params_at = [&](double xx) {
        return effect_params(e, xx, truth0, c.design, d0.coordinate_names, d0.pressure_names);
      };
      e.params = params_at(x);
      if (e.scope == "coordinate") {
        for (const auto& [name, v] : e.params) {
          (void)v;
          e.target = name.substr(name.find('.') + 1);
          break;
        }
        if (e.name == "angle_offset") e.target = "";  // both coordinates of the joint
      } else if (e.scope == "chamber") {
        e.target = d0.pressure_names[static_cast<std::size_t>(4 * e.cc + e.chamber)];
      }
      io::RobotSpec alone = truth0;
      alone.effects = {to_spec(e)};
      const ArmDescription da = build(alone);  // throws EffectBuildError
      (void)da;
      for (int step = 0; step < 8; ++step) {
        alone.effects = {to_spec(e)};
        const ArmDescription dd = build(alone);
        double impact = HUGE_VAL;
        try {
          const SimOut so = simulate_from_rest(dd, t_train, p_train, false, ref.q_rest);
          if (so.s.ok()) impact = max_coordinate_rms(so.s.angles, ref.s.angles);
        } catch (const std::runtime_error&) {
        }
        e.impact = impact;
        e.severity = x;
        if (!opt.calibrate) break;
        double nx = x;
        if (impact < 4 * opt.angle_noise) nx = std::min(x * 1.6, info.x_max);
        if (impact > 0.25) nx = std::max(x / 1.6, info.x_min);
        if (nx == x) break;
        x = nx;
        e.params = params_at(x);
        ++e.calibration_steps;
      }
      if (!std::isfinite(e.impact)) {
        last_error = "effect '" + e.name + "': the arm with it does not simulate";
        failed = true;
      } else if (e.impact < 4 * opt.angle_noise) {
        e.note = "weak: impact below 4 x noise at the cap";
      } else if (e.impact > 0.25) {
        e.note = "strong: impact above 0.25 rad at the cap";
      }
      c.effects.push_back(e);
    }
    if (failed) continue;

    // The true and declared robots.
    c.truth = truth0;
    for (const auto& e : c.effects) c.truth.effects.push_back(to_spec(e));
    const ArmDescription dt = build(c.truth);
    c.declared = truth0;
    c.declared.effects.clear();
    Rng rdec(opt.seed, "declared/" + std::to_string(attempt));
    for (auto& seg : c.declared.segments) {
      if (auto* cc = std::get_if<io::CCJointSpec>(&seg)) {
        cc->inertia_model = "lumped";
        Eigen::Vector2d fk, fd;
        for (int a = 0; a < 2; ++a) fk(a) = rdec.log_uniform(1 / 1.5, 1.5);
        for (int a = 0; a < 2; ++a) fd(a) = rdec.log_uniform(1 / 1.5, 1.5);
        cc->stiffness = cc->stiffness.cwiseProduct(fk);
        cc->damping = cc->damping.cwiseProduct(fd);
        c.declared_factors[cc->name] = {fk, fd};
      } else if (auto* r = std::get_if<io::RevoluteJointSpec>(&seg)) {
        const double fk = rdec.log_uniform(1 / 1.5, 1.5), fd = rdec.log_uniform(1 / 1.5, 1.5);
        r->stiffness *= fk;
        r->damping *= fd;
        c.declared_factors[r->name] = {Eigen::Vector2d(fk, 0), Eigen::Vector2d(fd, 0)};
      }
    }
    c.declared.name = truth0.name + ", declared";
    c.truth.name = truth0.name + ", truth";

    // The records, through the true description with tight tolerances.
    SimOut tr, te;
    try {
      tr = simulate_from_rest(dt, t_train, p_train, true, ref.q_rest);
      te = simulate_from_rest(dt, t_test, p_test, true, ref.q_rest);
    } catch (const std::runtime_error& e) {
      last_error = e.what();
      continue;
    }
    if (!tr.s.ok() || !te.s.ok()) {
      last_error = "true simulation: " + (tr.s.ok() ? te.s.result.message : tr.s.result.message);
      continue;
    }
    c.q_rest = tr.q_rest;
    c.max_angle = std::max(tr.s.angles.cwiseAbs().maxCoeff(), te.s.angles.cwiseAbs().maxCoeff());
    if (c.max_angle > 1.6) {
      last_error = "bends to " + std::to_string(c.max_angle) + " rad";
      continue;
    }
    const Eigen::Index nh = static_cast<Eigen::Index>(std::lround(opt.hold_seconds * opt.rate));
    for (const auto* s : {&tr.s, &te.s})
      for (Eigen::Index i = 0; i < std::min(nh, s->angles.rows()); ++i)
        c.hold_drift = std::max(c.hold_drift, (s->angles.row(i) - s->angles.row(0)).cwiseAbs().maxCoeff());
    Rng rn(opt.seed, "noise/" + std::to_string(attempt));
    c.train = noisy(dt, t_train, p_train, tr.s.angles, opt.angle_noise, opt.pressure_noise, rn, "train");
    c.test = noisy(dt, t_test, p_test, te.s.angles, opt.angle_noise, opt.pressure_noise, rn, "test");
    return c;
  }
  throw std::runtime_error("seed " + std::to_string(opt.seed) + ": no usable arm in " +
                           std::to_string(opt.max_attempts) + " draws (last: " + last_error + ")");
}

/// \brief Whether this build of the library accepts an effect with a scope's parameter names
/// (tried on a small two-joint arm); `why` gets the library's message when not.
inline bool effect_builds(const std::string& name, const std::string& scope, std::string* why) {
  using namespace detail;
  const EffectInfo* info = find_effect(name);
  if (!info) return false;
  io::RobotSpec s;
  s.gravity = Eigen::Vector3d(0, 0, 9.81);
  for (int j = 1; j <= 2; ++j)
    s.segments.push_back(io::make_cc_joint("joint" + std::to_string(j), 0.5, 0.15, 0.15, 0.04, 0.015,
                                           Eigen::Vector2d(10, 10), Eigen::Vector2d(0.5, 0.5)));
  ArmDesign des;
  for (int j = 0; j < 2; ++j) {
    JointDesign jd;
    jd.name = "joint" + std::to_string(j + 1);
    jd.segment = j;
    jd.dA = 3e-5;
    jd.pmax = 1e5;
    jd.theta = 0.5;
    jd.v90 = 1;
    des.cc.push_back(jd);
  }
  des.tip_mass = 0.5;
  InjectedEffect e;
  e.name = name;
  e.scope = scope;
  e.cc = 1;
  e.axis = 0;
  e.chamber = 2;
  e.aux = 0.5;
  e.aux2 = 1;
  if (scope == "shared") e.joints = {"joint1", "joint2"};
  else e.joints = {"joint2"};
  if (name == "payload") e.joints.clear();
  const ArmDescription d = build_arm(s);
  e.params = effect_params(e, 0.5 * (info->x_lo + info->x_hi), s, des, d.coordinate_names, d.pressure_names);
  s.effects = {to_spec(e)};
  try {
    build_arm(s);
    return true;
  } catch (const std::exception& ex) {
    if (why) *why = ex.what();
    return false;
  }
}

}  // namespace softrne::gen
