// Every effect type, through one typed suite (generated from AnyEffect, so a new effect cannot
// skip it: it needs a Law<> below or this file does not compile), and one physics test per
// effect added in interface v2.
//
// The Law<E> specialisations write each effect's law again, independently of its header (from
// formats.md section 4 and the headers' doc comments), on plain Eigen types.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/arm/arm_dynamics.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/sim/arm_simulation.hpp"
#include "softrne/sim/fixed_step.hpp"

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using softrne::AnyEffect;
using softrne::ArmDescription;
using softrne::ArmDynamics;
using softrne::ArmJoint;
using softrne::EffectBase;
using softrne::Scope;
using softrne::io::RobotSpec;

// ---- the test arm ---------------------------------------------------------------------------

softrne::io::RigidLinkSpec link(const std::string& name, double mass, double length, double ixx) {
  softrne::io::RigidLinkSpec l;
  l.name = name;
  l.mass = mass;
  l.length = length;
  l.com = Eigen::Vector3d(0, 0, length / 2);
  l.inertia = Eigen::Vector3d(ixx, ixx, 0.8 * ixx).asDiagonal();
  return l;
}

/// CC joint (4 chambers, eq. 24), link, revolute wrist, link, CC joint with 3 chambers at 0,
/// 120 and 240 degrees, link: every kind of joint and both pressure layouts. Coordinates
/// u1 v1 qwrist u2 v2; pressure channels p1_0..p1_3, p2_0..p2_2.
RobotSpec test_arm() {
  using softrne::io::make_cc_joint;
  RobotSpec s;
  s.name = "effects test arm";
  s.gravity = Eigen::Vector3d(0, 0, 9.81);
  s.segments.push_back(make_cc_joint("joint1", 0.8, 0.2, 0.2, 0.06, 0.03, Eigen::Vector2d(30, 26),
                                     Eigen::Vector2d(2.5, 2.0)));
  s.segments.push_back(link("link1", 1.0, 0.15, 0.004));
  softrne::io::RevoluteJointSpec w;
  w.name = "wrist";
  w.axis = Eigen::Vector3d(1, 0, 0);
  w.stiffness = 6.0;
  w.damping = 0.4;
  s.segments.push_back(w);
  s.segments.push_back(link("link2", 0.5, 0.08, 0.001));
  auto j2 = make_cc_joint("joint2", 0.6, 0.18, 0.18, 0.05, 0.028, Eigen::Vector2d(18, 15),
                          Eigen::Vector2d(1.2, 1.0));
  const double dA = 0.05 * M_PI * 0.028 * 0.028;
  j2.pressure_to_torque.resize(2, 3);
  for (int c = 0; c < 3; ++c) {
    const double a = 2 * M_PI * c / 3;
    j2.pressure_to_torque(0, c) = dA * std::cos(a);
    j2.pressure_to_torque(1, c) = dA * std::sin(a);
  }
  j2.custom_pressure_map = true;
  s.segments.push_back(j2);
  s.segments.push_back(link("link3", 0.3, 0.05, 0.0003));
  return s;
}

const RobotSpec& declared_spec() {
  static const RobotSpec s = test_arm();
  return s;
}
const ArmDescription& declared() {
  static const ArmDescription d = softrne::build_arm(declared_spec());
  return d;
}

// Names of the test arm, written out (formats.md section 4), per joint of the table.
const std::vector<std::string> kJointNames{"joint1", "wrist", "joint2"};
const std::vector<std::vector<std::string>> kCoordinateNames{
    {"u1", "v1"}, {"qwrist"}, {"u2", "v2"}};
const std::vector<std::vector<std::string>> kPressureNames{
    {"p1_0", "p1_1", "p1_2", "p1_3"}, {}, {"p2_0", "p2_1", "p2_2"}};

// ---- the laws, independently -----------------------------------------------------------------

/// Parameter `kind` of listed joint i (sub = coordinate or chamber), by the layout rule of the
/// contract: units in order, kinds contiguous within a unit.
double par(const EffectBase& e, std::size_t i, int kind, int sub, int num_kinds) {
  const auto& J = declared().joints;
  int unit = 0;
  switch (e.scope) {
    case Scope::Shared: unit = 0; break;
    case Scope::PerJoint: unit = static_cast<int>(i); break;
    case Scope::PerCoordinate:
      for (std::size_t l = 0; l < i; ++l) unit += J[static_cast<std::size_t>(e.joints[l])].nq;
      unit += sub;
      break;
    case Scope::PerChamber:
      for (std::size_t l = 0; l < i; ++l)
        unit += J[static_cast<std::size_t>(e.joints[l])].num_inputs;
      unit += sub;
      break;
  }
  return e.params(unit * num_kinds + kind);
}

/// What an effect may change, all in one place: forces, effective pressures, state
/// derivatives, measurement model, delay, the chain's inertia and gravity, the initial state.
struct Observed {
  VectorXd tau, p_eff, xsd, gain, offset, x0;
  double delay = 0;
  MatrixXd M;
  VectorXd G;
  VectorXd flat() const {
    std::vector<double> v;
    for (const VectorXd* a : {&tau, &p_eff, &xsd, &gain, &offset, &x0, &G})
      v.insert(v.end(), a->data(), a->data() + a->size());
    v.insert(v.end(), M.data(), M.data() + M.size());
    v.push_back(delay);
    return Eigen::Map<VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  }
};

/// Defaults: the effect changes nothing of that part.
struct NoLaw {
  static double random_state(std::mt19937& rng) {
    return std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
  }
  template <class E>
  static void pressures(const E&, const VectorXd&, VectorXd&) {}
  template <class E>
  static void forces(const E&, const VectorXd&, const VectorXd&, const VectorXd&, const VectorXd&,
                     VectorXd&) {}
  template <class E>
  static void derivative(const E&, const VectorXd&, const VectorXd&, const VectorXd&,
                         const VectorXd&, VectorXd&) {}
  template <class E>
  static void initial(const E&, const VectorXd&, const VectorXd&, VectorXd&) {}
  template <class E>
  static void measurement(const E&, VectorXd&, VectorXd&) {}
  template <class E>
  static double delay(const E&) { return 0; }
  template <class E>
  static void modify_spec(const E&, RobotSpec&) {}
  // Whether the neutral values make the model exactly the declared one.
  static constexpr bool kExactNeutral = true;
};

/// Loops over the listed joints: f(i, joint).
template <class E, class F>
void each_joint(const E& e, F&& f) {
  for (std::size_t i = 0; i < e.joints.size(); ++i)
    f(i, declared().joints[static_cast<std::size_t>(e.joints[i])]);
}

template <class E>
struct Law;  // one specialisation per effect: a new effect without one does not compile

template <>
struct Law<softrne::Stiffening> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd& q, const VectorXd&, const VectorXd&,
                     const VectorXd&, VectorXd& tau) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      const double phi2 = q.segment(j.q_offset, j.nq).squaredNorm();
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= par(e, i, 0, k, 1) * j.stiffness(k) * phi2 * q(j.q_offset + k);
    });
  }
};

template <>
struct Law<softrne::PressureStiffening> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd& q, const VectorXd&, const VectorXd& p,
                     const VectorXd&, VectorXd& tau) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      const double sum = p.segment(j.input_offset, j.num_inputs).sum();
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= par(e, i, 0, k, 1) * 1e-6 * sum * j.stiffness(k) * q(j.q_offset + k);
    });
  }
};

template <>
struct Law<softrne::ActuatorLag> : NoLaw {
  static double random_state(std::mt19937& rng) {
    return std::uniform_real_distribution<double>(0.0, 150e3)(rng);
  }
  template <class E>
  static void pressures(const E& e, const VectorXd& xs, VectorXd& p) {
    int s = 0;
    each_joint(e, [&](std::size_t, const ArmJoint& j) {
      for (int c = 0; c < j.num_inputs; ++c) p(j.input_offset + c) = xs(s++);
    });
  }
  template <class E>
  static void derivative(const E& e, const VectorXd& xs, const VectorXd&, const VectorXd&,
                         const VectorXd& p, VectorXd& xsd) {
    int s = 0;
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int c = 0; c < j.num_inputs; ++c, ++s)
        xsd(s) = (p(j.input_offset + c) - xs(s)) / par(e, i, 0, c, 1);
    });
  }
  template <class E>
  static void initial(const E& e, const VectorXd&, const VectorXd& p0, VectorXd& xs) {
    int s = 0;
    each_joint(e, [&](std::size_t, const ArmJoint& j) {
      for (int c = 0; c < j.num_inputs; ++c) xs(s++) = p0(j.input_offset + c);
    });
  }
  // T = 1 ms is practically, not exactly, no lag.
  static constexpr bool kExactNeutral = false;
};

template <>
struct Law<softrne::CoulombFriction> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd&, const VectorXd& qd, const VectorXd&,
                     const VectorXd&, VectorXd& tau) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k)
        tau(j.q_offset + k) -= par(e, i, 0, k, 1) * std::tanh(qd(j.q_offset + k) / 0.02);
    });
  }
};

template <>
struct Law<softrne::QuadraticDamping> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd&, const VectorXd& qd, const VectorXd&,
                     const VectorXd&, VectorXd& tau) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k) {
        const double v = qd(j.q_offset + k);
        tau(j.q_offset + k) -= par(e, i, 0, k, 1) * std::abs(v) * v;
      }
    });
  }
};

template <>
struct Law<softrne::ChamberMisalignment> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd&, const VectorXd&, const VectorXd& p,
                     const VectorXd&, VectorXd& tau) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      const Eigen::Vector2d t = j.pressure_to_torque * p.segment(j.input_offset, j.num_inputs);
      const double psi = par(e, i, 0, 0, 1);
      Eigen::Matrix2d R;
      R << std::cos(psi), -std::sin(psi), std::sin(psi), std::cos(psi);
      tau.segment<2>(j.q_offset) += (R - Eigen::Matrix2d::Identity()) * t;
    });
  }
};

template <>
struct Law<softrne::Payload> : NoLaw {
  template <class E>
  static void modify_spec(const E& e, RobotSpec& s) {
    softrne::io::RigidLinkSpec m;  // a point mass at the last distal frame
    m.name = "test payload";
    m.mass = e.params(0);
    m.length = 0;
    m.com.setZero();
    m.inertia.setZero();
    s.segments.push_back(m);
  }
};

template <>
struct Law<softrne::AngleOffset> : NoLaw {
  template <class E>
  static void measurement(const E& e, VectorXd&, VectorXd& offset) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k) offset(j.q_offset + k) += par(e, i, 0, k, 1);
    });
  }
};

template <>
struct Law<softrne::Viscoelastic> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd& q, const VectorXd&, const VectorXd&,
                     const VectorXd& z, VectorXd& tau) {
    int s = 0;
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k, ++s)
        tau(j.q_offset + k) -= par(e, i, 0, k, 2) * (q(j.q_offset + k) - z(s));
    });
  }
  template <class E>
  static void derivative(const E& e, const VectorXd& z, const VectorXd& q, const VectorXd&,
                         const VectorXd&, VectorXd& zd) {
    int s = 0;
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k, ++s)
        zd(s) = (q(j.q_offset + k) - z(s)) / par(e, i, 1, k, 2);
    });
  }
  template <class E>
  static void initial(const E& e, const VectorXd& q0, const VectorXd&, VectorXd& z) {
    int s = 0;
    each_joint(e, [&](std::size_t, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k) z(s++) = q0(j.q_offset + k);
    });
  }
};

template <>
struct Law<softrne::ChamberGain> : NoLaw {
  template <class E>
  static void pressures(const E& e, const VectorXd&, VectorXd& p) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int c = 0; c < j.num_inputs; ++c) p(j.input_offset + c) *= par(e, i, 0, c, 1);
    });
  }
};

template <>
struct Law<softrne::InputDelay> : NoLaw {
  template <class E>
  static double delay(const E& e) { return e.params(0); }
};

template <>
struct Law<softrne::Hysteresis> : NoLaw {
  template <class E>
  static void forces(const E& e, const VectorXd&, const VectorXd&, const VectorXd&,
                     const VectorXd& F, VectorXd& tau) {
    int s = 0;
    each_joint(e, [&](std::size_t, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k) tau(j.q_offset + k) -= F(s++);
    });
  }
  template <class E>
  static void derivative(const E& e, const VectorXd& F, const VectorXd&, const VectorXd& qd,
                         const VectorXd&, VectorXd& Fd) {
    int s = 0;
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k, ++s) {
        const double fmax = par(e, i, 0, k, 2), sigma = par(e, i, 1, k, 2);
        const double v = qd(j.q_offset + k);
        Fd(s) = fmax > 0 ? sigma * (v - std::hypot(v, 1e-4) * F(s) / fmax) : 0.0;
      }
    });
  }
};

template <>
struct Law<softrne::MassScale> : NoLaw {
  template <class E>
  static void modify_spec(const E& e, RobotSpec& s) {
    auto scale = [&](std::size_t seg, double f) {
      if (auto* cc = std::get_if<softrne::io::CCJointSpec>(&s.segments[seg])) cc->mass *= f;
      if (auto* l = std::get_if<softrne::io::RigidLinkSpec>(&s.segments[seg])) {
        l->mass *= f;
        l->inertia *= f;
      }
    };
    if (e.scope == Scope::Shared) {
      for (std::size_t k = 0; k < s.segments.size(); ++k) scale(k, e.params(0));
      return;
    }
    // Per joint: the joint's segment and the links after it, up to the next joint. In the
    // test arm: joint1 -> segments 0, 1; wrist -> 2, 3; joint2 -> 4, 5.
    for (std::size_t i = 0; i < e.joints.size(); ++i) {
      const std::size_t first = 2 * static_cast<std::size_t>(e.joints[i]);
      scale(first, e.params(static_cast<Eigen::Index>(i)));
      scale(first + 1, e.params(static_cast<Eigen::Index>(i)));
    }
  }
};

template <>
struct Law<softrne::SensorGain> : NoLaw {
  template <class E>
  static void measurement(const E& e, VectorXd& gain, VectorXd&) {
    each_joint(e, [&](std::size_t i, const ArmJoint& j) {
      for (int k = 0; k < j.nq; ++k) gain(j.q_offset + k) *= par(e, i, 0, k, 1);
    });
  }
};

// ---- model vs law ------------------------------------------------------------------------------

struct Point {
  VectorXd x, p, y0;  // state, recorded pressures, first measured row
};

/// The model's side of Observed for description d.
Observed model_side(const ArmDescription& d, const Point& pt) {
  Observed o;
  const int n = d.nq, ne = d.num_effect_states;
  const VectorXd q = pt.x.head(n), qd = pt.x.segment(n, n), xs = pt.x.tail(ne);
  ArmDynamics<double> f(d);
  o.p_eff.resize(d.num_inputs);
  f.effective_pressures(xs, pt.p, o.p_eff);
  o.tau = f.joint_forces(q, qd, o.p_eff, xs);
  o.xsd.resize(ne);
  f.effect_state_derivative(xs, q, qd, pt.p, o.xsd);
  d.measurement(o.gain, o.offset);
  o.delay = d.input_delay();
  auto chain = d.make_chain<double>();
  auto data = chain.make_data();
  o.M = softrne::mass_matrix(chain, data, q);
  o.G = softrne::rnea(chain, data, q, VectorXd::Zero(n), VectorXd::Zero(n));
  o.x0 = softrne::initial_state(d, pt.y0, pt.p);
  return o;
}

/// The law's side: the declared model written out plus Law<E>.
template <class E>
Observed law_side(const E& e, const Point& pt) {
  const ArmDescription& d0 = declared();
  Observed o;
  const int n = d0.nq;
  const int ne = static_cast<int>(pt.x.size()) - 2 * n;
  const VectorXd q = pt.x.head(n), qd = pt.x.segment(n, n), xs = pt.x.tail(ne);
  o.p_eff = pt.p;
  Law<E>::pressures(e, xs, o.p_eff);
  o.tau = VectorXd::Zero(n);
  for (const auto& j : d0.joints)
    for (int k = 0; k < j.nq; ++k)
      o.tau(j.q_offset + k) =
          j.pressure_to_torque.row(k).dot(o.p_eff.segment(j.input_offset, j.num_inputs)) -
          j.stiffness(k) * q(j.q_offset + k) - j.damping(k) * qd(j.q_offset + k);
  Law<E>::forces(e, q, qd, o.p_eff, xs, o.tau);
  o.xsd = VectorXd::Zero(ne);
  Law<E>::derivative(e, xs, q, qd, pt.p, o.xsd);
  o.gain = VectorXd::Ones(n);
  o.offset = VectorXd::Zero(n);
  Law<E>::measurement(e, o.gain, o.offset);
  o.delay = Law<E>::delay(e);
  RobotSpec s = declared_spec();
  Law<E>::modify_spec(e, s);
  const ArmDescription dm = softrne::build_arm(s);
  auto chain = dm.make_chain<double>();
  auto data = chain.make_data();
  o.M = softrne::mass_matrix(chain, data, q);
  o.G = softrne::rnea(chain, data, q, VectorXd::Zero(n), VectorXd::Zero(n));
  o.x0 = VectorXd::Zero(2 * n + ne);
  const VectorXd q0 = (pt.y0 - o.offset).cwiseQuotient(o.gain);
  o.x0.head(n) = q0;
  VectorXd xs0 = VectorXd::Zero(ne);
  Law<E>::initial(e, q0, pt.p, xs0);
  o.x0.tail(ne) = xs0;
  return o;
}

template <class E>
Point random_point(const ArmDescription& d, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Point pt;
  pt.x.resize(d.num_states());
  for (int i = 0; i < d.nq; ++i) pt.x(i) = 0.6 * U(rng);
  for (int i = d.nq; i < 2 * d.nq; ++i) pt.x(i) = 2.0 * U(rng);
  for (int i = 2 * d.nq; i < d.num_states(); ++i) pt.x(i) = Law<E>::random_state(rng);
  pt.p.resize(d.num_inputs);
  for (int i = 0; i < d.num_inputs; ++i) pt.p(i) = 75e3 + 75e3 * U(rng);
  pt.y0.resize(d.nq);
  for (int i = 0; i < d.nq; ++i) pt.y0(i) = 0.5 * U(rng);
  return pt;
}

/// Parameters drawn inside their bounds (away from the ends, so that finite differences stay
/// inside), uniform or log-uniform.
void randomise(AnyEffect& e, const ArmDescription& d, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(0.1, 0.9);
  EffectBase& b = softrne::effect_base(e);
  for (Eigen::Index k = 0; k < b.params.size(); ++k) {
    const auto bd = softrne::effect_param_bounds(e, static_cast<int>(k), d.segment_mass());
    b.params(k) = bd.log_scale ? std::exp(std::log(bd.lower) +
                                          U(rng) * (std::log(bd.upper) - std::log(bd.lower)))
                               : bd.lower + U(rng) * (bd.upper - bd.lower);
  }
}

ArmDescription with_effect(const AnyEffect& e) {
  ArmDescription d = declared();
  softrne::add_effect(d, e);
  return d;
}

void expect_close(const VectorXd& a, const VectorXd& b, double rel, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  if (a.size() == 0) return;  // (maxCoeff of nothing is undefined)
  const double scale = std::max(1.0, b.cwiseAbs().maxCoeff());
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), rel * scale) << what;
}

std::string where(const AnyEffect& e) {
  return softrne::effect_name(e) + " (" + softrne::scope_name(softrne::effect_base(e).scope) + ")";
}

// ---- the typed suite -------------------------------------------------------------------------

template <class V>
struct TypesOf;
template <class... E>
struct TypesOf<std::variant<E...>> {
  using type = ::testing::Types<E...>;
};
using AllEffects = TypesOf<AnyEffect>::type;

template <class E>
class EveryEffect : public ::testing::Test {
 protected:
  /// The effect at its neutral values on every joint it applies to, for each allowed scope.
  std::vector<AnyEffect> neutral_in_every_scope() const {
    std::vector<AnyEffect> out;
    for (Scope s : E::scopes)
      out.push_back(softrne::make_effect_at_neutral(E::name, declared(), s));
    return out;
  }
  std::mt19937 rng{2024};
};
TYPED_TEST_SUITE(EveryEffect, AllEffects);

TYPED_TEST(EveryEffect, DescribesItself) {
  using E = TypeParam;
  AnyEffect e = E{};
  EXPECT_EQ(softrne::effect_name(e), E::name);
  EXPECT_GE(softrne::effect_num_kinds(e), 1);
  EXPECT_FALSE(softrne::effect_scopes(e).empty());
  bool applies_somewhere = false;
  for (const auto& j : declared().joints) applies_somewhere |= softrne::effect_applies_to(e, j);
  EXPECT_TRUE(applies_somewhere);
  for (int k = 0; k < softrne::effect_num_kinds(e); ++k) {
    const softrne::ParamInfo info = softrne::effect_param_info(e, k);
    EXPECT_LT(info.lower, info.upper) << info.name;
    EXPECT_GE(info.neutral, info.lower) << info.name;
    EXPECT_LE(info.neutral, info.upper) << info.name;
    if (info.log_scale) {
      EXPECT_GT(info.lower, 0) << info.name;
    }
    EXPECT_NE(std::string(info.unit), "") << info.name;
  }
  // A scope it does not allow is refused.
  for (Scope s : {Scope::Shared, Scope::PerJoint, Scope::PerCoordinate, Scope::PerChamber})
    if (!softrne::effect_scope_allowed(e, s)) {
      EXPECT_THROW(softrne::make_effect_at_neutral(E::name, declared(), s), std::invalid_argument);
    }
}

// `reduces_to` (effect_reduces_to) names another effect whose kinds are this one's first
// kinds (same units) and which allows every scope this one does, so that the loop can refit
// it in the same scope from the same values.
TYPED_TEST(EveryEffect, ItsSimplerLimitIsAnEffectWithItsFirstKinds) {
  using E = TypeParam;
  const AnyEffect e = E{};
  const std::string simpler = softrne::effect_reduces_to(e);
  if (simpler.empty()) return;  // most effects have none; hysteresis has (its own test below)
  AnyEffect s;
  ASSERT_TRUE(softrne::make_effect(simpler, s)) << simpler;
  EXPECT_NE(softrne::effect_name(s), E::name);
  ASSERT_LT(softrne::effect_num_kinds(s), softrne::effect_num_kinds(e));
  for (int k = 0; k < softrne::effect_num_kinds(s); ++k)
    EXPECT_EQ(std::string(softrne::effect_param_info(s, k).unit), softrne::effect_param_info(e, k).unit);
  for (Scope sc : E::scopes) EXPECT_TRUE(softrne::effect_scope_allowed(s, sc)) << softrne::scope_name(sc);
  // The loop starts the simpler limit where the richer fit ended: per unit, the first kinds.
  for (const AnyEffect& rich_neutral : this->neutral_in_every_scope()) {
    AnyEffect rich = rich_neutral;
    const EffectBase& b = softrne::effect_base(rich);
    Eigen::VectorXd& p = softrne::effect_base(rich).params;
    for (Eigen::Index i = 0; i < p.size(); ++i) p(i) = 10.0 * static_cast<double>(i) + 1.0;
    const AnyEffect simple_neutral = softrne::make_effect_at_neutral(simpler, declared(), b.scope, b.joints);
    const Eigen::VectorXd r = softrne::effect_reduced_params(rich, simple_neutral);
    const int kr = softrne::effect_num_kinds(rich), ks = softrne::effect_num_kinds(simple_neutral);
    ASSERT_EQ(r.size(), softrne::effect_num_params(simple_neutral, declared().joints)) << softrne::scope_name(b.scope);
    for (Eigen::Index u = 0; u < r.size() / ks; ++u)
      for (int k = 0; k < ks; ++k) EXPECT_EQ(r(u * ks + k), p(u * kr + k)) << softrne::scope_name(b.scope);
  }
  EXPECT_THROW(softrne::effect_reduced_params(s, e), std::invalid_argument);
}

TYPED_TEST(EveryEffect, ParameterNamesFollowTheRobotFileRules) {
  for (const AnyEffect& e : this->neutral_in_every_scope()) {
    const EffectBase& b = softrne::effect_base(e);
    std::vector<std::string> expected;
    std::vector<std::string> suffixes;
    for (int j : b.joints) {
      const auto jj = static_cast<std::size_t>(j);
      if (b.scope == Scope::PerJoint) suffixes.push_back("." + kJointNames[jj]);
      if (b.scope == Scope::PerCoordinate)
        for (const auto& c : kCoordinateNames[jj]) suffixes.push_back("." + c);
      if (b.scope == Scope::PerChamber)
        for (const auto& c : kPressureNames[jj]) suffixes.push_back("." + c);
    }
    if (b.scope == Scope::Shared) suffixes = {""};
    for (const auto& s : suffixes)
      for (int k = 0; k < softrne::effect_num_kinds(e); ++k)
        expected.push_back(softrne::effect_param_info(e, k).name + s);
    EXPECT_EQ(softrne::effect_param_names(e, declared()), expected) << where(e);
    EXPECT_EQ(softrne::effect_num_params(e, declared().joints), static_cast<int>(expected.size()));
    EXPECT_EQ(b.params.size(), static_cast<Eigen::Index>(expected.size()));
  }
}

// (a), (c): the model equals the law at random parameters and states, in every scope.
TYPED_TEST(EveryEffect, ModelEqualsItsLawInEveryScope) {
  using E = TypeParam;
  for (AnyEffect e : this->neutral_in_every_scope()) {
    for (int trial = 0; trial < 4; ++trial) {
      randomise(e, declared(), this->rng);
      const ArmDescription d = with_effect(e);
      const Point pt = random_point<E>(d, this->rng);
      const Observed m = model_side(d, pt), l = law_side(std::get<E>(e), pt);
      const std::string w = where(e);
      expect_close(m.tau, l.tau, 1e-12, w + ": joint forces");
      expect_close(m.p_eff, l.p_eff, 1e-12, w + ": effective pressures");
      expect_close(m.xsd, l.xsd, 1e-12, w + ": state derivative");
      expect_close(m.gain, l.gain, 1e-15, w + ": measurement gain");
      expect_close(m.offset, l.offset, 1e-15, w + ": measurement offset");
      expect_close(m.x0, l.x0, 1e-12, w + ": initial state");
      EXPECT_EQ(m.delay, l.delay) << w;
      expect_close(Eigen::Map<const VectorXd>(m.M.data(), m.M.size()),
                   Eigen::Map<const VectorXd>(l.M.data(), l.M.size()), 1e-12, w + ": M");
      expect_close(m.G, l.G, 1e-12, w + ": gravity");
    }
  }
}

// (a): each parameter changes what the law says it changes, by as much (central differences
// of the model against central differences of the law), and none is dead.
TYPED_TEST(EveryEffect, EachParameterActsAsItsLawSays) {
  using E = TypeParam;
  for (AnyEffect e : this->neutral_in_every_scope()) {
    randomise(e, declared(), this->rng);
    const Point pt = random_point<E>(with_effect(e), this->rng);
    EffectBase& b = softrne::effect_base(e);
    for (Eigen::Index k = 0; k < b.params.size(); ++k) {
      const auto bd =
          softrne::effect_param_bounds(e, static_cast<int>(k), declared().segment_mass());
      const double h = 1e-5 * (bd.upper - bd.lower), v = b.params(k);
      b.params(k) = v + h;
      const VectorXd mp = model_side(with_effect(e), pt).flat();
      const VectorXd lp = law_side(std::get<E>(e), pt).flat();
      b.params(k) = v - h;
      const VectorXd mm = model_side(with_effect(e), pt).flat();
      const VectorXd lm = law_side(std::get<E>(e), pt).flat();
      b.params(k) = v;
      const VectorXd dm = (mp - mm) / (2 * h), dl = (lp - lm) / (2 * h);
      const std::string w = where(e) + " parameter " + std::to_string(k);
      EXPECT_GT(dm.cwiseAbs().maxCoeff(), 1e-9) << w << " changes nothing";
      EXPECT_LE((dm - dl).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, dl.cwiseAbs().maxCoeff()))
          << w;
    }
  }
}


// ---- simulation helpers ------------------------------------------------------------------------

softrne::sim::ArmSimulationOptions tight() {
  softrne::sim::ArmSimulationOptions o;
  o.cvode.rtol = 1e-10;
  o.cvode.atol = 1e-10;
  o.cvode.max_steps = 2000000;
  o.velocity_atol_factor = 1.0;
  return o;
}

/// Smooth recorded pressures: 101 samples over 1 s.
double smooth_pressure(double t, int c) { return 60e3 + 40e3 * std::sin(3.0 * t + c); }
struct Input {
  VectorXd t;
  MatrixXd P;
};
Input smooth_input(int channels) {
  Input in;
  in.t = VectorXd::LinSpaced(101, 0.0, 1.0);
  in.P.resize(in.t.size(), channels);
  for (Eigen::Index i = 0; i < in.t.size(); ++i)
    for (int c = 0; c < channels; ++c) in.P(i, c) = smooth_pressure(in.t(i), c);
  return in;
}

/// x' = f(x, p(t)) for the fixed-step integrator, with the smooth pressures written out.
struct FixedStepArm {
  ArmDynamics<double>* f;
  VectorXd p;
  void rhs(double t, const VectorXd& x, VectorXd& xd) {
    for (Eigen::Index c = 0; c < p.size(); ++c) p(c) = smooth_pressure(t, static_cast<int>(c));
    f->rhs(x, p, xd);
  }
};

/// Angles (nq x steps) of 200 RK4 steps of 5 ms from x0.
MatrixXd rk4_angles(const ArmDescription& d, const VectorXd& x0) {
  ArmDynamics<double> f(d);
  FixedStepArm sys{&f, VectorXd(d.num_inputs)};
  softrne::sim::Rk4Workspace<VectorXd> work(d.num_states());
  VectorXd x = x0;
  MatrixXd q(d.nq, 200);
  for (int i = 0; i < 200; ++i) {
    softrne::sim::rk4_step(sys, 0.005 * i, x, 0.005, work);
    q.col(i) = x.head(d.nq);
  }
  return q;
}

// (b): at its neutral values the model is the declared model.
TYPED_TEST(EveryEffect, AtItsNeutralValuesTheModelIsTheDeclaredOne) {
  using E = TypeParam;
  const ArmDescription& d0 = declared();
  for (const AnyEffect& e : this->neutral_in_every_scope()) {
    const ArmDescription d = with_effect(e);
    const std::string w = where(e);
    for (int trial = 0; trial < 3; ++trial) {
      // Effect states where the simulation starts them (from q and p).
      Point pt = random_point<E>(d, this->rng);
      pt.x.tail(d.num_effect_states) =
          softrne::initial_state(d, pt.x.head(d.nq), pt.p).tail(d.num_effect_states);
      Point p0 = pt;
      p0.x = pt.x.head(2 * d.nq);
      const Observed m = model_side(d, pt), o = model_side(d0, p0);
      expect_close(m.tau, o.tau, 1e-14, w + ": joint forces");
      expect_close(m.p_eff, o.p_eff, 1e-14, w + ": effective pressures");
      expect_close(m.gain, o.gain, 0, w + ": measurement gain");
      expect_close(m.offset, o.offset, 0, w + ": measurement offset");
      expect_close(m.x0.head(2 * d.nq), o.x0, 0, w + ": initial coordinates");
      EXPECT_EQ(m.delay, 0.0) << w;
      expect_close(Eigen::Map<const VectorXd>(m.M.data(), m.M.size()),
                   Eigen::Map<const VectorXd>(o.M.data(), o.M.size()), 1e-14, w + ": M");
      expect_close(m.G, o.G, 1e-14, w + ": gravity");
    }
    // A short simulation (CVODE; from a bent start, so that every term acts).
    const Input in = smooth_input(d.num_inputs);
    VectorXd y0(d.nq);
    for (int i = 0; i < d.nq; ++i) y0(i) = 0.2 - 0.07 * i;
    const auto s0 = softrne::sim::simulate_arm(d0, in.t, in.P, y0, tight());
    const auto s1 = softrne::sim::simulate_arm(d, in.t, in.P, y0, tight());
    ASSERT_TRUE(s0.ok() && s1.ok()) << w << ": " << s1.result.message;
    const double diff = (s1.angles - s0.angles).cwiseAbs().maxCoeff();
    EXPECT_GT(s0.angles.cwiseAbs().maxCoeff(), 0.1);  // the arm moves
    if (d.num_effect_states == 0) {
      // The same ODE: the same steps, bit for bit up to the order of additions.
      EXPECT_LE(diff, 1e-12) << w;
    } else if (Law<E>::kExactNeutral) {
      // Own states join CVODE's error norm and change its steps: integrator tolerance.
      EXPECT_LE(diff, 1e-7) << w;
    } else {
      // actuator_lag at T = 1 ms: the pressures lag by about 1 ms, the angles by about
      // 1 ms times their rate (below 1.5 rad/s here).
      std::printf("[   info   ] %s at neutral: max |angle difference| = %.2e rad\n", w.c_str(),
                  diff);
      EXPECT_LE(diff, 2e-3) << w;
      EXPECT_GT(diff, 1e-6) << w;  // and it is a lag, not nothing
    }
    // Fixed steps: the same arithmetic on q whatever the states do, so exact.
    if (Law<E>::kExactNeutral) {
      VectorXd x0 = softrne::initial_state(d, y0, in.P.row(0).transpose());
      const MatrixXd q1 = rk4_angles(d, x0);
      const MatrixXd q0 = rk4_angles(d0, x0.head(2 * d.nq));
      EXPECT_LE((q1 - q0).cwiseAbs().maxCoeff(), 1e-12) << w << " (RK4)";
      EXPECT_GT(q0.cwiseAbs().maxCoeff(), 0.1);
    }
  }
}

MatrixXd central_differences(softrne::sim::ArmSystem& sys, double t, const VectorXd& x) {
  const int n = sys.size();
  MatrixXd J(n, n);
  VectorXd fp(n), fm(n);
  for (int j = 0; j < n; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(x(j)));
    VectorXd xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    EXPECT_TRUE(sys.rhs(t, xp, fp));
    EXPECT_TRUE(sys.rhs(t, xm, fm));
    J.col(j) = (fp - fm) / (2 * h);
  }
  return J;
}

// (c): the AutoDiff Jacobian of the simulator (both ways of forming it) differentiates the
// effect's forces and states correctly.
TYPED_TEST(EveryEffect, SimulatorJacobianMatchesFiniteDifferences) {
  using E = TypeParam;
  using JM = softrne::sim::ArmSimulationOptions::JacobianMethod;
  for (AnyEffect e : this->neutral_in_every_scope()) {
    randomise(e, declared(), this->rng);
    const ArmDescription d = with_effect(e);
    const Input in = smooth_input(d.num_inputs);
    softrne::sim::ArmSystem sys(d, in.t, in.P,
                                softrne::sim::ArmSimulationOptions::PressureInterpolation::pchip);
    for (int trial = 0; trial < 2; ++trial) {
      const Point pt = random_point<E>(d, this->rng);
      const int n = sys.size();
      const double t = 0.31 + 0.2 * trial;
      VectorXd f(n);
      ASSERT_TRUE(sys.rhs(t, pt.x, f));
      const MatrixXd J_fd = central_differences(sys, t, pt.x);
      const double scale = std::max(1.0, J_fd.cwiseAbs().maxCoeff());
      for (JM m : {JM::inverse_dynamics, JM::forward_dynamics}) {
        MatrixXd J = MatrixXd::Zero(n, n);
        sys.set_jacobian_method(m);
        ASSERT_TRUE(sys.jacobian(t, pt.x, f, J));
        EXPECT_LE((J - J_fd).cwiseAbs().maxCoeff(), 1e-7 * scale)
            << where(e) << (m == JM::inverse_dynamics ? " (inverse)" : " (forward)");
      }
    }
  }
}

// (d): robot file round trip in every scope.
TYPED_TEST(EveryEffect, RobotFileRoundTripInEveryScope) {
  for (AnyEffect e : this->neutral_in_every_scope()) {
    randomise(e, declared(), this->rng);
    const ArmDescription d = with_effect(e);
    const RobotSpec spec = softrne::to_robot_spec(d);
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("softrne-effects-" + where(e) + ".json"))
                                 .string();
    softrne::io::write_robot_json(spec, path);
    const RobotSpec read = softrne::io::read_robot_json(path);
    std::filesystem::remove(path);
    for (const RobotSpec* s : {&spec, &read}) {
      const ArmDescription d2 = softrne::build_arm(*s);
      ASSERT_EQ(d2.effects.size(), 1u);
      const EffectBase& a = softrne::effect_base(d.effects[0]);
      const EffectBase& b = softrne::effect_base(d2.effects[0]);
      EXPECT_EQ(softrne::effect_name(d2.effects[0]), softrne::effect_name(e));
      EXPECT_EQ(b.scope, a.scope) << where(e);
      EXPECT_EQ(b.joints, a.joints) << where(e);
      EXPECT_EQ(b.params, a.params) << where(e);  // exactly: numbers round-trip
      EXPECT_EQ(d2.num_effect_states, d.num_effect_states);
    }
  }
}

/// build_arm(bad) throws a one-line std::invalid_argument containing every part.
void expect_bad(const RobotSpec& bad, const std::vector<std::string>& parts) {
  try {
    softrne::build_arm(bad);
    ADD_FAILURE() << "no error for " << parts.back();
  } catch (const std::invalid_argument& ex) {
    const std::string msg = ex.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    for (const auto& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos) << msg << "\nlacks: " << p;
  }
}

TYPED_TEST(EveryEffect, BadParameterNamesGiveOneLineErrors) {
  using E = TypeParam;
  const auto scopes = this->neutral_in_every_scope();
  const RobotSpec good = softrne::to_robot_spec(with_effect(scopes[0]));
  const std::string effect = std::string("effects[0] '") + E::name + "'";
  const std::string kind = E::param_info[0].name;
  RobotSpec bad = good;
  bad.effects[0].params["bogus"] = 1.0;
  expect_bad(bad, {effect, "field 'params.bogus'", "unknown kind"});
  bad = good;
  bad.effects[0].params[kind + ".nosuch"] = 1.0;
  expect_bad(bad, {effect, "field 'params." + kind + ".nosuch'"});
  bad = good;
  bad.effects[0].params.clear();
  expect_bad(bad, {effect, "field 'params'", "no parameters"});
  if (good.effects[0].params.size() > 1) {
    bad = good;
    const std::string gone = bad.effects[0].params.rbegin()->first;
    bad.effects[0].params.erase(gone);
    expect_bad(bad, {effect, "field 'params'", "missing '" + gone + "'"});
  }
  if (scopes.size() > 1) {
    // Names of two scopes in one entry.
    const RobotSpec other = softrne::to_robot_spec(with_effect(scopes[1]));
    bad = good;
    bad.effects[0].params.insert(*other.effects[0].params.begin());
    expect_bad(bad, {effect, "field 'params'", "mixes scopes"});
  }
  bad = good;
  bad.effects[0].name = "no_such_effect";
  expect_bad(bad, {"effects[0] 'no_such_effect'", "field 'name'", "unknown effect"});
}

// ---- physics of the effects of interface v2 ---------------------------------------------------

/// Effect `name` on every joint it applies to, with scope and parameters given.
AnyEffect effect(const std::string& name, Scope scope, const std::vector<double>& params) {
  AnyEffect e = softrne::make_effect_at_neutral(name, declared(), scope);
  EffectBase& b = softrne::effect_base(e);
  EXPECT_EQ(b.params.size(), static_cast<Eigen::Index>(params.size())) << name;
  for (std::size_t k = 0; k < params.size(); ++k)
    b.params(static_cast<Eigen::Index>(k)) = params[k];
  return e;
}

TEST(Viscoelastic, AStepInTheAngleGivesAForceRelaxingWithTau) {
  const double k_b = 20.0, tau = 0.3;
  const ArmDescription d = with_effect(effect("viscoelastic", Scope::Shared, {k_b, tau}));
  ArmDynamics<double> f(d), f0(declared());
  // Relaxed at q = 0, then q jumps to q1 and stays: z(t) = q1 (1 - exp(-t/tau)), so the
  // branch adds -k_b q1 exp(-t/tau).
  VectorXd q1(d.nq);
  q1 << 0.3, -0.2, 0.5, 0.1, 0.25;
  const VectorXd qd = VectorXd::Zero(d.nq), p = VectorXd::Constant(d.num_inputs, 5e4);
  VectorXd z = softrne::initial_state(d, VectorXd::Zero(d.nq), p).tail(d.num_effect_states);
  ASSERT_EQ(z.size(), d.nq);
  EXPECT_EQ(z.cwiseAbs().maxCoeff(), 0.0);
  auto force = [&](const VectorXd& zz) {
    VectorXd pe(d.num_inputs);
    f.effective_pressures(zz, p, pe);
    return VectorXd(f.joint_forces(q1, qd, pe, zz) - f0.joint_forces(q1, qd, p, VectorXd()));
  };
  auto zdot = [&](const VectorXd& zz) {
    VectorXd r(zz.size());
    f.effect_state_derivative(zz, q1, qd, p, r);
    return r;
  };
  const double dt = 1e-3;
  double worst = 0;
  for (int i = 1; i <= 1500; ++i) {  // RK4 on the branch's own state, 5 tau
    const VectorXd k1 = zdot(z), k2 = zdot(z + 0.5 * dt * k1), k3 = zdot(z + 0.5 * dt * k2),
                   k4 = zdot(z + dt * k3);
    z += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    const VectorXd expected = -k_b * q1 * std::exp(-i * dt / tau);
    worst = std::max(worst, (force(z) - expected).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-10 * k_b);
  EXPECT_LT(force(z).cwiseAbs().maxCoeff(), k_b * 0.5 * std::exp(-4.9));  // relaxed
}

TEST(ChamberGain, ZeroGainOnAChamberRemovesItsColumnFromKprs) {
  // chamber p2_1 (joint2, chamber 1) silenced; every other gain 1.
  std::vector<double> g(7, 1.0);
  g[5] = 0.0;
  const ArmDescription d = with_effect(effect("chamber_gain", Scope::PerChamber, g));
  RobotSpec s = declared_spec();
  std::get<softrne::io::CCJointSpec>(s.segments[4]).pressure_to_torque.col(1).setZero();
  const ArmDescription removed = softrne::build_arm(s);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const Point pt = random_point<softrne::ChamberGain>(d, rng);
    ArmDynamics<double> f(d), fr(removed);
    VectorXd pe(d.num_inputs);
    f.effective_pressures(VectorXd(), pt.p, pe);
    const VectorXd qd = pt.x.segment(d.nq, d.nq), q = pt.x.head(d.nq);
    EXPECT_LE((f.joint_forces(q, qd, pe, VectorXd()) - fr.joint_forces(q, qd, pt.p, VectorXd()))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-13);
  }
  const Input in = smooth_input(d.num_inputs);
  const auto a = softrne::sim::simulate_arm(d, in.t, in.P, VectorXd(), tight());
  const auto b = softrne::sim::simulate_arm(removed, in.t, in.P, VectorXd(), tight());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LE((a.angles - b.angles).cwiseAbs().maxCoeff(), 1e-12);
  // And the chamber did matter.
  const auto c = softrne::sim::simulate_arm(declared(), in.t, in.P, VectorXd(), tight());
  EXPECT_GT((a.angles - c.angles).cwiseAbs().maxCoeff(), 1e-2);
}

TEST(ChamberGain, ComposesWithActuatorLagInEitherOrder) {
  const AnyEffect lag = effect("actuator_lag", Scope::Shared, {0.05});
  const AnyEffect gain = effect("chamber_gain", Scope::PerJoint, {0.7, 1.3});
  ArmDescription a = declared(), b = declared();
  softrne::add_effect(a, lag);
  softrne::add_effect(a, gain);
  softrne::add_effect(b, gain);
  softrne::add_effect(b, lag);
  std::mt19937 rng(3);
  VectorXd xs(7), p(7);
  for (int i = 0; i < 7; ++i) {
    xs(i) = 1e5 * std::uniform_real_distribution<double>(0, 1)(rng);
    p(i) = 1e5 * std::uniform_real_distribution<double>(0, 1)(rng);
  }
  VectorXd pa(7), pb(7), expected(7);
  ArmDynamics<double>(a).effective_pressures(xs, p, pa);
  ArmDynamics<double>(b).effective_pressures(xs, p, pb);
  expected << 0.7 * xs.head(4), 1.3 * xs.tail(3);  // the gain scales the lagged pressures
  EXPECT_LE((pa - expected).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE((pb - expected).cwiseAbs().maxCoeff(), 1e-9);
}

/// Pressure step at t = 0.2 s on chambers 0 and 4 (from 0, the hanging arm at rest).
Input pressure_step() {
  Input in;
  in.t = VectorXd::LinSpaced(121, 0.0, 1.2);
  in.P = MatrixXd::Zero(in.t.size(), 7);
  for (Eigen::Index i = 0; i < in.t.size(); ++i)
    if (in.t(i) >= 0.2 - 1e-12) {
      in.P(i, 0) = 1e5;
      in.P(i, 4) = 8e4;
    }
  return in;
}

TEST(InputDelay, TheResponseToAPressureStepIsTheUndelayedOneShifted) {
  using PI = softrne::sim::ArmSimulationOptions::PressureInterpolation;
  const double delay = 0.05;  // 5 samples
  const ArmDescription d = with_effect(effect("input_delay", Scope::Shared, {delay}));
  EXPECT_EQ(d.input_delay(), delay);
  const Input in = pressure_step();
  for (PI mode : {PI::pchip, PI::linear, PI::zero_order_hold}) {
    auto o = tight();
    o.interpolation = mode;
    const auto a = softrne::sim::simulate_arm(declared(), in.t, in.P, VectorXd(), o);
    const auto b = softrne::sim::simulate_arm(d, in.t, in.P, VectorXd(), o);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_GT(a.angles.cwiseAbs().maxCoeff(), 0.05);
    double worst = 0;
    for (Eigen::Index i = 0; i < in.t.size(); ++i) {
      // Before the delayed step the pressures are the first sample's: the arm hangs at rest.
      const VectorXd expected =
          i >= 5 ? VectorXd(a.angles.row(i - 5).transpose()) : VectorXd::Zero(d.nq);
      worst = std::max(worst, (b.angles.row(i).transpose() - expected).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-7) << "interpolation " << static_cast<int>(mode);
  }
}

TEST(SensorGain, SimulatedAnglesAreTheGainTimesTheUngainedOnes) {
  const std::vector<double> s{0.9, 1.1, 0.8, 1.25, 0.95};
  const ArmDescription d = with_effect(effect("sensor_gain", Scope::PerCoordinate, s));
  const Eigen::Map<const VectorXd> gain(s.data(), 5);
  const Input in = smooth_input(d.num_inputs);
  VectorXd q0(5);
  q0 << 0.1, -0.05, 0.3, 0.0, 0.2;
  const auto a = softrne::sim::simulate_arm(declared(), in.t, in.P, q0, tight());
  // The sensors read gain .* q0 at the start: the simulation starts from the same q0.
  const auto b = softrne::sim::simulate_arm(d, in.t, in.P, gain.cwiseProduct(q0), tight());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_LE((b.states - a.states).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LE((b.angles - a.angles * gain.asDiagonal()).cwiseAbs().maxCoeff(), 1e-14);
  // With an angle offset too: y = s q + b.
  ArmDescription both = d;
  softrne::add_effect(both,
                      effect("angle_offset", Scope::PerCoordinate, {0.01, 0.02, -0.03, 0, 0.05}));
  VectorXd off(5);
  off << 0.01, 0.02, -0.03, 0, 0.05;
  const auto c =
      softrne::sim::simulate_arm(both, in.t, in.P, gain.cwiseProduct(q0) + off, tight());
  ASSERT_TRUE(c.ok());
  EXPECT_LE((c.states - a.states).cwiseAbs().maxCoeff(), 1e-12);
  MatrixXd expected = a.angles * gain.asDiagonal();
  expected.rowwise() += off.transpose();
  EXPECT_LE((c.angles - expected).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(MassScale, ScalesTheMassMatrixAndGravityOfOneCCJoint) {
  RobotSpec one;
  one.gravity = Eigen::Vector3d(0.3, -0.2, 9.81);
  one.segments.push_back(softrne::io::make_cc_joint("joint1", 0.8, 0.2, 0.2, 0.06, 0.03,
                                                    Eigen::Vector2d(30, 26),
                                                    Eigen::Vector2d(2.5, 2.0)));
  one.effects.push_back({"mass_scale", {"joint1"}, {{"scale.joint1", 1.7}}, ""});
  const ArmDescription scaled = softrne::build_arm(one);
  one.effects.clear();
  const ArmDescription plain = softrne::build_arm(one);
  auto c1 = scaled.make_chain<double>();
  auto c0 = plain.make_chain<double>();
  auto d1 = c1.make_data();
  auto d0 = c0.make_data();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector2d q(U(rng), U(rng)), qd(2 * U(rng), 2 * U(rng)), qdd(U(rng), U(rng));
    const MatrixXd M1 = softrne::mass_matrix(c1, d1, q), M0 = softrne::mass_matrix(c0, d0, q);
    EXPECT_LE((M1 - 1.7 * M0).cwiseAbs().maxCoeff(), 1e-14 * M0.cwiseAbs().maxCoeff());
    // The whole inverse dynamics scales (inertia, Coriolis, gravity).
    const VectorXd t1 = softrne::rnea(c1, d1, q, qd, qdd), t0 = softrne::rnea(c0, d0, q, qd, qdd);
    EXPECT_LE((t1 - 1.7 * t0).cwiseAbs().maxCoeff(), 1e-13 * t0.cwiseAbs().maxCoeff());
  }
}

TEST(MassScale, PerJointScalesTheJointAndItsLinksOnly) {
  const ArmDescription d = with_effect(effect("mass_scale", Scope::PerJoint, {2.0, 0.5, 1.5}));
  const std::vector<double> expected{2.0, 2.0, 0.5, 0.5, 1.5, 1.5};
  EXPECT_EQ(d.segment_mass_scale(), expected);
  const ArmDescription shared = with_effect(effect("mass_scale", Scope::Shared, {1.3}));
  EXPECT_EQ(shared.segment_mass_scale(), std::vector<double>(6, 1.3));
}

// RK4 on the effect states of `f` (from zero) with every coordinate driven by q = A sin(w t)
// and zero pressures; after step i (of `steps`, of length dt) calls
// visit(i, q, qdot, states) with q, qdot at the end of the step.
template <class Visit>
void drive_effect_states_by_a_sinusoid(ArmDynamics<double>& f, const ArmDescription& d, double A,
                                       double w, double dt, int steps, Visit&& visit) {
  const VectorXd p = VectorXd::Zero(d.num_inputs);
  auto q_at = [&](double t) { return VectorXd(VectorXd::Constant(d.nq, A * std::sin(w * t))); };
  auto qd_at = [&](double t) { return VectorXd(VectorXd::Constant(d.nq, A * w * std::cos(w * t))); };
  auto xdot = [&](double t, const VectorXd& x) {
    VectorXd r(x.size());
    f.effect_state_derivative(x, q_at(t), qd_at(t), p, r);
    return r;
  };
  VectorXd x = VectorXd::Zero(d.num_effect_states);
  for (int i = 0; i < steps; ++i) {
    const double t = i * dt;
    const VectorXd k1 = xdot(t, x), k2 = xdot(t + dt / 2, x + dt / 2 * k1),
                   k3 = xdot(t + dt / 2, x + dt / 2 * k2), k4 = xdot(t + dt, x + dt * k3);
    x += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    visit(i, q_at(t + dt), qd_at(t + dt), x);
  }
}

TEST(Hysteresis, ASlowSinusoidTracesALoopThatSaturatesAtFmax) {
  const double f_max = 0.4, sigma = 60.0, A = 0.3;
  const ArmDescription d = with_effect(effect("hysteresis", Scope::Shared, {f_max, sigma}));
  ArmDynamics<double> f(d);
  const VectorXd p = VectorXd::Zero(d.num_inputs);
  // The Dahl state of coordinate 0 driven by q = A sin(w t) (the same on every coordinate),
  // by RK4 on the effect's own state derivative, over 2.25 periods.
  auto run = [&](double w, std::vector<double>& qs, std::vector<double>& Fs) {
    drive_effect_states_by_a_sinusoid(f, d, A, w, 2 * M_PI / w / 20000, 45000,
                                      [&](int, const VectorXd& q, const VectorXd&, const VectorXd& F) {
                                        qs.push_back(q(0));
                                        Fs.push_back(F(0));
                                      });
  };
  std::vector<double> q_slow, F_slow, q_fast, F_fast;
  run(0.5, q_slow, F_slow);
  run(2.0, q_fast, F_fast);
  // Saturates at Fmax and never exceeds it.
  double F_hi = -1e9, F_lo = 1e9;
  for (double F : F_slow) {
    F_hi = std::max(F_hi, F);
    F_lo = std::min(F_lo, F);
  }
  EXPECT_LE(F_hi, f_max);
  EXPECT_GT(F_hi, f_max * (1 - 1e-4));
  EXPECT_LT(F_lo, -f_max * (1 - 1e-4));
  EXPECT_GE(F_lo, -f_max);
  // On the rising branch of the second period, from a point i0 shortly after the reversal at
  // q = -A (where |qdot| >> eps), the Dahl law gives
  // F(q) = Fmax - (Fmax - F(i0)) exp(-sigma (q - q(i0)) / Fmax), whatever the rate.
  const std::size_t n = 20000, rev = n + n / 4 * 3;  // q = -A at 3/4 of a period
  EXPECT_LT(F_slow[rev - 1], -f_max * (1 - 1e-3));  // the falling branch had saturated
  const std::size_t i0 = rev + 800;
  EXPECT_LT(F_slow[i0], 0.8 * f_max);  // still on the transient: the check means something
  double worst = 0;
  for (std::size_t i = i0; i < rev + n / 4; ++i) {  // up to q = 0
    const double expected =
        f_max - (f_max - F_slow[i0]) * std::exp(-sigma * (q_slow[i] - q_slow[i0]) / f_max);
    worst = std::max(worst, std::abs(F_slow[i] - expected));
  }
  EXPECT_LT(worst, 1e-4 * f_max);
  // Rate independence: the loop at 4x the frequency is the same curve F(q).
  double rate = 0;
  for (std::size_t i = n; i < 2 * n; ++i) rate = std::max(rate, std::abs(F_slow[i] - F_fast[i]));
  EXPECT_LT(rate, 1e-3 * f_max);
  // A loop: at q = 0 rising, F = +Fmax (nearly); at q = 0 falling, F = -Fmax (nearly).
  EXPECT_GT(F_slow[n], 0.99 * f_max);          // t = T: q = 0, rising
  EXPECT_LT(F_slow[n + n / 2], -0.99 * f_max);  // t = 1.5 T: q = 0, falling
  // The force is -F on every coordinate.
  VectorXd Fs = VectorXd::Constant(d.num_effect_states, 0.3);
  VectorXd pe(d.num_inputs);
  f.effective_pressures(Fs, p, pe);
  ArmDynamics<double> f0(declared());
  const VectorXd q = VectorXd::Zero(d.nq);
  EXPECT_LE((f.joint_forces(q, q, pe, Fs) - f0.joint_forces(q, q, p, VectorXd()) +
             VectorXd::Constant(d.nq, 0.3))
                .cwiseAbs()
                .maxCoeff(),
            1e-15);
}

// The limit hysteresis declares (reduces_to = coulomb_friction): with a Dahl stiffness at the
// top of its range, the force along q = A sin(w t) is Coulomb friction's -Fc tanh(qdot / v_s)
// with Fc = Fmax, except within a few v_s of the reversals, where the two smoothings differ.
TEST(Hysteresis, AtItsLargestStiffnessItIsCoulombFriction) {
  const double f_max = 0.4, A = 0.3, w = 2.0;
  const double sigma = softrne::Hysteresis::param_info[1].upper;
  const ArmDescription dh = with_effect(effect("hysteresis", Scope::Shared, {f_max, sigma}));
  const ArmDescription dc = with_effect(effect("coulomb_friction", Scope::Shared, {f_max}));
  ArmDynamics<double> fh(dh), fc(dc);
  const VectorXd pe = VectorXd::Zero(dh.num_inputs);
  double worst = 0, near_reversal = 0;
  // Two periods, the second one checked.
  drive_effect_states_by_a_sinusoid(
      fh, dh, A, w, 2 * M_PI / w / 200000, 400000,
      [&](int i, const VectorXd& q, const VectorXd& qd, const VectorXd& F) {
        if (i < 200000) return;
        const double diff =
            (fh.joint_forces(q, qd, pe, F) - fc.joint_forces(q, qd, pe, VectorXd())).cwiseAbs().maxCoeff();
        if (std::abs(qd(0)) > 5 * softrne::CoulombFriction::kSmoothingSpeed)
          worst = std::max(worst, diff);
        else
          near_reversal = std::max(near_reversal, diff);
      });
  EXPECT_LT(worst, 1e-3 * f_max);
  EXPECT_GT(near_reversal, 0.1 * f_max);  // the comparison did cross the reversals
}

TEST(RobotFile, ParameterNamesAreCheckedWhenRead) {
  auto robot = [](const std::string& params) {
    return std::string(R"({"format": "softrne-robot/1", "gravity": [0, 0, 9.81],
      "segments": [{"type": "cc_joint", "name": "joint1", "mass": 0.8, "height": 0.2,
        "diameter": 0.2, "chamber_distance": 0.06, "chamber_radius": 0.03,
        "stiffness": [30, 26], "damping": [2.5, 2.0]}],
      "effects": [{"name": "stiffening", "joints": ["joint1"], "params": )") +
           params + "}]}";
  };
  for (const std::string bad : {R"({"beta.": 1.0})", R"({".u1": 1.0})"}) {
    try {
      softrne::io::parse_robot_json(robot(bad), "mem.json");
      ADD_FAILURE() << "no error for " << bad;
    } catch (const softrne::io::InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      EXPECT_NE(msg.find("mem.json"), std::string::npos) << msg;
      EXPECT_NE(msg.find("effects[0] 'stiffening'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("field 'params."), std::string::npos) << msg;
    }
  }
  // Well formed: read, and build_arm infers the scope from the names.
  const RobotSpec s =
      softrne::io::parse_robot_json(robot(R"({"beta.u1": 1.0, "beta.v1": 2.0})"), "mem.json");
  const ArmDescription d = softrne::build_arm(s);
  ASSERT_EQ(d.effects.size(), 1u);
  EXPECT_EQ(softrne::effect_base(d.effects[0]).scope, Scope::PerCoordinate);
  EXPECT_EQ(softrne::effect_base(d.effects[0]).params, Eigen::Vector2d(1.0, 2.0));
  // A mix, read from a file: the one-line error names the file, the effect and the field.
  const RobotSpec mixed =
      softrne::io::parse_robot_json(robot(R"({"beta": 1.0, "beta.v1": 2.0})"), "mem.json");
  expect_bad(mixed, {"mem.json", "effects[0] 'stiffening'", "field 'params'", "mixes scopes"});
}

// The joints table is the one place the springs, dampers and pressure maps live once a fit has
// changed them: the chain built from the description carries them (not the robot file's
// declared values), and the model's joint forces are the chain's segments' own, -K q - D qd +
// K_prs p written out here from the table.
TEST(ArmDynamics, JointForcesAreTheFittedJointsOfTheTable) {
  ArmDescription d = declared();
  for (auto& j : d.joints) {
    j.stiffness *= 1.7;
    j.damping *= 0.4;
    j.pressure_to_torque *= 1.3;
  }
  const auto chain = d.make_chain<double>();
  for (const auto& j : d.joints)
    std::visit(
        [&](const auto& seg) {
          using Seg = std::decay_t<decltype(seg)>;
          if constexpr (Seg::nq == 2) {
            EXPECT_EQ(seg.stiffness, j.stiffness);
            EXPECT_EQ(seg.damping, j.damping);
            EXPECT_EQ(Eigen::MatrixXd(seg.pressure_to_torque), Eigen::MatrixXd(j.pressure_to_torque));
          } else if constexpr (Seg::nq == 1) {
            EXPECT_EQ(seg.stiffness, j.stiffness(0));
            EXPECT_EQ(seg.damping, j.damping(0));
          } else {
            ADD_FAILURE() << j.name << ": a joint of the table on a segment without coordinates";
          }
        },
        chain.segment(j.segment));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VectorXd q(d.nq), qd(d.nq), p(d.num_inputs);
  for (int i = 0; i < d.nq; ++i) { q(i) = 0.5 * u(rng); qd(i) = u(rng); }
  for (int i = 0; i < d.num_inputs; ++i) p(i) = 2e4 * (1.0 + u(rng));
  ArmDynamics<double> f(d);
  const VectorXd tau = f.joint_forces(q, qd, p, VectorXd());
  VectorXd expected(d.nq);
  for (const auto& j : d.joints)
    for (int k = 0; k < j.nq; ++k) {
      double t = -j.stiffness(k) * q(j.q_offset + k) - j.damping(k) * qd(j.q_offset + k);
      for (int c = 0; c < j.num_inputs; ++c) t += j.pressure_to_torque(k, c) * p(j.input_offset + c);
      expected(j.q_offset + k) = t;
    }
  EXPECT_LT((tau - expected).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + expected.cwiseAbs().maxCoeff()));
  // The same forces from the declared values differ: the test can fail.
  ArmDynamics<double> f0(declared());
  EXPECT_GT((f0.joint_forces(q, qd, p, VectorXd()) - expected).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
