// softrne-bench: timings of the core algorithms (Google Benchmark), side by side with
// Pinocchio when it was found at configure time. docs/performance.md explains every figure.
//
// Benchmark names: <model>/<implementation>/<algorithm>[/<n>]
//   calc/{cc,revolute,rigid_link}          one segment's calc (kinematics of one segment)
//   arm/{static,dynamic}/<algo>            the paper's arm (3 x [CC joint + rigid link]) as
//                                          softrne::Chain<...> and as softrne::DynamicChain
//   cc/dynamic/<algo>/<n>                  n x [CC joint + rigid link], runtime chain
//   rev<N>/{static,dynamic}/<algo>         N x [revolute joint + rigid link]
//   rev<N>/pinocchio/<fn>                  the same chain in Pinocchio (RX/RY/RZ joints)
//   rev<N>/pinocchio_unaligned/<fn>        ... with JointModelRevoluteUnaligned
//   sim/arm-a-1/{train,test}[/atol1e-08]   CVODE simulation (softrne::sim::simulate_arm) of
//                                          examples/data/arm-a-1/<split>.csv, default options
//                                          [or absolute tolerance 1e-8]
// with <algo> in rnea, gravity, bias, mass_matrix, forward_dynamics, aba, rnea_derivatives,
// aba_derivatives (algorithms/derivatives.hpp) and <fn> in rnea,
// gravity (computeGeneralizedGravity), bias (nonLinearEffects), crba, aba,
// rnea_derivatives (computeRNEADerivatives), aba_derivatives (computeABADerivatives).
//
// Every call goes through a non-inlined wrapper (as Pinocchio's benchmark/timings.cpp does)
// and cycles through kStates random states prepared beforehand. After the runs, a summary
// prints the ratios the issue asks for, computed from the medians (or from the single run
// when there are no repetitions) of this very run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include "softrne/softrne.hpp"

#ifdef SOFTRNE_BENCH_WITH_PINOCCHIO
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#endif

#ifdef SOFTRNE_BENCH_WITH_SIM
#include "softrne/arm/arm_description.hpp"
#include "softrne/io/csv.hpp"
#include "softrne/io/robot_json.hpp"
#include "softrne/sim/arm_simulation.hpp"
#endif

#define SOFTRNE_BENCH_NOINLINE __attribute__((noinline))

namespace {

using namespace softrne;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;
using CC = ConstantCurvatureJoint<double>;
using Link = RigidLink<double>;
using Rev = RevoluteJoint<double>;

constexpr int kStates = 16;  // states cycled through by every benchmark (power of two)

/// Every benchmark body by name, for --profile (one call per invocation, state k % kStates).
std::map<std::string, std::function<void(unsigned)>>& bodies() {
  static std::map<std::string, std::function<void(unsigned)>> m;
  return m;
}

// ---------------------------------------------------------------------------------------
// Models

/// A CC joint of examples/data/arm-a-1/robot.json (stiffness and damping play no role here).
CC arm_cc() {
  CC c;
  c.mass = 0.8;
  c.height = 0.2;
  c.diameter = 0.2;
  c.pressure_to_torque = CC::four_chamber_map(0.06, 0.03);
  c.stiffness << 23.37, 37.12;
  c.damping << 2.50, 2.46;
  return c;
}

/// A rigid link of robot.json: centre of mass on the axis, diagonal inertia.
Link arm_link(double mass, double length, double ixx, double izz) {
  Link l;
  l.mass = mass;
  l.length = length;
  l.com = Vector3d(0, 0, length / 2);
  l.inertia = Vector3d(ixx, ixx, izz).asDiagonal();
  return l;
}
Link arm_link_12() {
  return arm_link(1.5, 0.15, 0.0052125, 0.0048);
}
Link arm_link_3() {
  return arm_link(0.4, 0.05, 1.0 / 3000.0, 0.0005);
}

using StaticArm = Chain<CC, Link, CC, Link, CC, Link>;

StaticArm make_static_arm() {
  StaticArm c(arm_cc(), arm_link_12(), arm_cc(), arm_link_12(), arm_cc(), arm_link_3());
  c.gravity = Vector3d(0, 0, 9.81);
  return c;
}

DynamicChain<double> make_dynamic_arm() {
  DynamicChain<double> c;
  for (int j = 0; j < 3; ++j) {
    c.add(arm_cc(), "joint" + std::to_string(j + 1));
    c.add(j == 2 ? arm_link_3() : arm_link_12(), "link" + std::to_string(j + 1));
  }
  c.gravity = Vector3d(0, 0, 9.81);
  return c;
}

/// n x [CC joint + rigid link] of the arm's dimensions, hanging.
DynamicChain<double> make_cc_chain(int n) {
  DynamicChain<double> c;
  for (int j = 0; j < n; ++j) {
    c.add(arm_cc());
    c.add(arm_link_12());
  }
  c.gravity = Vector3d(0, 0, 9.81);
  return c;
}

/// Joint axis of revolute joint j: z, y, x, z, y, x, ... (an anthropomorphic-arm pattern).
int rev_axis_index(int j) {
  return 2 - j % 3;
}

/// The link after revolute joint j: off-axis centre of mass, full inertia tensor.
Link rev_link(int j) {
  Link l;
  l.mass = 2.0 / (1.0 + 0.2 * j);
  l.length = 0.25;
  l.com = Vector3d(0.01, -0.02, 0.12);
  const Matrix3d A =
      (Matrix3d() << 0.020, 0.001, -0.002, 0.001, 0.018, 0.0015, -0.002, 0.0015, 0.006).finished();
  l.inertia = A * (l.mass / 2.0);
  return l;
}

/// N x [revolute joint + rigid link], gravity -z.
DynamicChain<double> make_rev_chain(int n) {
  DynamicChain<double> c;
  for (int j = 0; j < n; ++j) {
    Rev r;
    r.axis = Vector3d::Unit(rev_axis_index(j));
    c.add(r);
    c.add(rev_link(j));
  }
  return c;
}

using StaticRev6 = Chain<Rev, Link, Rev, Link, Rev, Link, Rev, Link, Rev, Link, Rev, Link>;

/// Copies the segments of a runtime chain into a compile-time chain of the same layout.
template <class StaticChain>
StaticChain to_static(const DynamicChain<double>& d) {
  StaticChain s;
  int i = 0;
  std::apply(
      [&](auto&... seg) { ((seg = std::get<std::decay_t<decltype(seg)>>(d.segment(i++))), ...); },
      s.segments);
  s.gravity = d.gravity;
  s.inertia_rate = d.inertia_rate;
  return s;
}

// ---------------------------------------------------------------------------------------
// Fixtures: a chain, its workspace and kStates random states.

template <class ChainT>
struct ChainFixture {
  using VectorQ = typename ChainT::VectorQ;
  ChainT chain;
  typename ChainT::Data data;
  std::vector<VectorQ> q, qd, qdd, tau;
  int n = 0;  // what the plots use as size (CC segments or revolute joints)

  ChainFixture(ChainT c, int size, unsigned seed = 42)
      : chain(std::move(c)), data(chain.make_data()), n(size) {
    const int nq = chain.num_coordinates();
    std::mt19937 rng(seed);
    auto vec = [&](double scale) {
      std::uniform_real_distribution<double> u(-scale, scale);
      VectorQ v(nq);
      for (int i = 0; i < nq; ++i) v(i) = u(rng);
      return v;
    };
    for (int k = 0; k < kStates; ++k) {
      q.push_back(vec(1.0));
      qd.push_back(vec(2.0));
      qdd.push_back(vec(5.0));
      tau.push_back(vec(5.0));
    }
  }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

// Non-inlined calls: what a user's code pays for one evaluation.
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::VectorQ& call_rnea(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q,
    const typename ChainT::VectorQ& qd, const typename ChainT::VectorQ& qdd) {
  return rnea(c, d, q, qd, qdd);
}
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::VectorQ& call_gravity(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q) {
  return gravity(c, d, q);
}
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::VectorQ& call_bias(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q,
    const typename ChainT::VectorQ& qd) {
  return bias(c, d, q, qd, true);  // C qdot + G, like Pinocchio's nonLinearEffects
}
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::MatrixQ& call_mass_matrix(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q) {
  return mass_matrix(c, d, q);
}
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::VectorQ& call_forward_dynamics(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q,
    const typename ChainT::VectorQ& qd, const typename ChainT::VectorQ& tau) {
  return forward_dynamics(c, d, q, qd, tau);
}
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::VectorQ& call_aba(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q,
    const typename ChainT::VectorQ& qd, const typename ChainT::VectorQ& tau) {
  return aba(c, d, q, qd, tau);
}

template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::MatrixQ& call_rnea_derivatives(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q,
    const typename ChainT::VectorQ& qd, const typename ChainT::VectorQ& qdd) {
  rnea_derivatives(c, d, q, qd, qdd);
  return d.dtau_dq;
}
template <class ChainT>
SOFTRNE_BENCH_NOINLINE const typename ChainT::MatrixQ& call_aba_derivatives(
    const ChainT& c, typename ChainT::Data& d, const typename ChainT::VectorQ& q,
    const typename ChainT::VectorQ& qd, const typename ChainT::VectorQ& tau) {
  aba_derivatives(c, d, q, qd, tau);
  return d.dqddot_dq;
}

enum Algo : unsigned {
  kRnea = 1,
  kGravity = 2,
  kBias = 4,
  kMassMatrix = 8,
  kForwardDynamics = 16,
  kAba = 32,  // O(n) forward dynamics (articulated_body.hpp)
  kRneaDerivatives = 64,  // derivatives.hpp
  kAbaDerivatives = 128,
  kAll = 255
};

benchmark::TimeUnit unit_for(double expected_ns) {
  if (expected_ns < 2e4) return benchmark::kNanosecond;
  if (expected_ns < 2e7) return benchmark::kMicrosecond;
  return benchmark::kMillisecond;
}

void set_counters(benchmark::State& st, int n, int nq) {
  st.counters["n"] = n;
  st.counters["nq"] = nq;
}

/// Registers the algorithms in `which` for one fixture under prefix/<algo>[suffix].
/// `ns_per_pass` is a rough cost of one RNE pass, only used to pick a readable time unit.
template <class ChainT>
void register_chain(const std::string& prefix, const std::string& suffix,
                    std::shared_ptr<ChainFixture<ChainT>> f, unsigned which, double ns_per_pass) {
  const int nq = f->chain.num_coordinates();
  auto reg = [&](const char* algo, double passes, auto body) {
    const std::string name = prefix + "/" + algo + suffix;
    bodies()[name] = [f, body](unsigned k) { body(*f, k & (kStates - 1)); };
    benchmark::RegisterBenchmark(name.c_str(), [f, body, nq](benchmark::State& st) {
      unsigned k = 0;
      for (auto _ : st) {
        body(*f, k & (kStates - 1));
        ++k;
      }
      set_counters(st, f->n, nq);
    })->Unit(unit_for(ns_per_pass * passes));
  };
  using Fix = ChainFixture<ChainT>;
  if (which & kRnea)
    reg("rnea", 1, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(call_rnea(x.chain, x.data, x.q[k], x.qd[k], x.qdd[k]).data());
    });
  if (which & kGravity)
    reg("gravity", 1, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(call_gravity(x.chain, x.data, x.q[k]).data());
    });
  if (which & kBias)
    reg("bias", 1, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(call_bias(x.chain, x.data, x.q[k], x.qd[k]).data());
    });
  if (which & kMassMatrix)
    reg("mass_matrix", 0.4 * nq, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(call_mass_matrix(x.chain, x.data, x.q[k]).data());
    });
  if (which & kForwardDynamics)
    reg("forward_dynamics", 0.4 * nq + 1e-3 * nq * nq, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(
          call_forward_dynamics(x.chain, x.data, x.q[k], x.qd[k], x.tau[k]).data());
    });
  if (which & kAba)
    reg("aba", 2.5, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(call_aba(x.chain, x.data, x.q[k], x.qd[k], x.tau[k]).data());
    });
  if (which & kRneaDerivatives)
    reg("rnea_derivatives", 4.0 * nq, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(
          call_rnea_derivatives(x.chain, x.data, x.q[k], x.qd[k], x.qdd[k]).data());
    });
  if (which & kAbaDerivatives)
    reg("aba_derivatives", 4.0 * nq, [](Fix& x, unsigned k) {
      benchmark::DoNotOptimize(
          call_aba_derivatives(x.chain, x.data, x.q[k], x.qd[k], x.tau[k]).data());
    });
}

// ---------------------------------------------------------------------------------------
// Single-segment calc

template <class Segment>
SOFTRNE_BENCH_NOINLINE void call_calc(const Segment& s,
                                      const Eigen::Matrix<double, Segment::nq, 1>& q,
                                      const Eigen::Matrix<double, Segment::nq, 1>& qd,
                                      typename Segment::Kinematics& kin) {
  s.calc(q, qd, kin);
}

template <class Segment>
void register_calc(const std::string& name, Segment seg, double qscale) {
  using VQ = Eigen::Matrix<double, Segment::nq, 1>;
  struct Fix {
    Segment seg;
    typename Segment::Kinematics kin;
    std::vector<VQ, Eigen::aligned_allocator<VQ>> q, qd;
    EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  };
  auto f = std::make_shared<Fix>();
  f->seg = seg;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < kStates; ++k) {
    VQ a, b;
    for (int i = 0; i < Segment::nq; ++i) {
      a(i) = qscale * u(rng);
      b(i) = 2.0 * u(rng);
    }
    f->q.push_back(a);
    f->qd.push_back(b);
  }
  bodies()["calc/" + name] = [f](unsigned k) {
    const unsigned i = k & (kStates - 1);
    call_calc(f->seg, f->q[i], f->qd[i], f->kin);
  };
  benchmark::RegisterBenchmark(("calc/" + name).c_str(), [f](benchmark::State& st) {
    unsigned k = 0;
    for (auto _ : st) {
      const unsigned i = k++ & (kStates - 1);
      call_calc(f->seg, f->q[i], f->qd[i], f->kin);
      benchmark::DoNotOptimize(f->kin.R_base_distal.data());
      benchmark::ClobberMemory();
    }
  });
}

// ---------------------------------------------------------------------------------------
// Pinocchio: the same revolute chains.

#ifdef SOFTRNE_BENCH_WITH_PINOCCHIO
namespace pin = pinocchio;

/// Joint j of a revolute chain sits at the distal frame of link j-1 (translation along z by
/// its length); link j's body is attached to joint j with its centre of mass and inertia.
pin::Model make_pinocchio_rev_chain(const DynamicChain<double>& c, bool unaligned) {
  pin::Model m;
  pin::JointIndex parent = 0;
  pin::SE3 placement = pin::SE3::Identity();
  for (int i = 0; i < c.num_segments(); ++i) {
    if (const auto* r = std::get_if<Rev>(&c.segment(i))) {
      const std::string name = "j" + std::to_string(i);
      if (unaligned) {
        parent = m.addJoint(parent, pin::JointModelRevoluteUnaligned(r->axis), placement, name);
      } else if (r->axis.isApprox(Vector3d::UnitX())) {
        parent = m.addJoint(parent, pin::JointModelRX(), placement, name);
      } else if (r->axis.isApprox(Vector3d::UnitY())) {
        parent = m.addJoint(parent, pin::JointModelRY(), placement, name);
      } else {
        parent = m.addJoint(parent, pin::JointModelRZ(), placement, name);
      }
      placement = pin::SE3::Identity();
    } else if (const auto* l = std::get_if<Link>(&c.segment(i))) {
      // Body fixed in the current frame, which is `placement` relative to the last joint.
      const pin::Inertia Y(l->mass, l->com, l->inertia);
      m.appendBodyToJoint(parent, Y, placement);
      placement = placement * pin::SE3(Matrix3d::Identity(), Vector3d(0, 0, l->length));
    }
  }
  m.gravity.linear(c.gravity);
  return m;
}

struct PinocchioFixture {
  pin::Model model;
  pin::Data data;
  std::vector<VectorXd> q, qd, qdd, tau;
  int n;
  PinocchioFixture(pin::Model m, const ChainFixture<DynamicChain<double>>& same, int size)
      : model(std::move(m)),
        data(model),
        q(same.q),
        qd(same.qd),
        qdd(same.qdd),
        tau(same.tau),
        n(size) {}
};

SOFTRNE_BENCH_NOINLINE const VectorXd& pin_rnea(const pin::Model& m, pin::Data& d,
                                                const VectorXd& q, const VectorXd& v,
                                                const VectorXd& a) {
  return pin::rnea(m, d, q, v, a);
}
SOFTRNE_BENCH_NOINLINE const VectorXd& pin_gravity(const pin::Model& m, pin::Data& d,
                                                   const VectorXd& q) {
  return pin::computeGeneralizedGravity(m, d, q);
}
SOFTRNE_BENCH_NOINLINE const VectorXd& pin_nle(const pin::Model& m, pin::Data& d, const VectorXd& q,
                                               const VectorXd& v) {
  return pin::nonLinearEffects(m, d, q, v);
}
SOFTRNE_BENCH_NOINLINE const Eigen::MatrixXd& pin_crba(const pin::Model& m, pin::Data& d,
                                                       const VectorXd& q) {
  return pin::crba(m, d, q, pin::Convention::LOCAL);
}
SOFTRNE_BENCH_NOINLINE const VectorXd& pin_aba(const pin::Model& m, pin::Data& d, const VectorXd& q,
                                               const VectorXd& v, const VectorXd& tau) {
  return pin::aba(m, d, q, v, tau, pin::Convention::LOCAL);
}

// (Pinocchio's derivative matrices are row-major: their data pointer is returned.)
SOFTRNE_BENCH_NOINLINE const double* pin_rnea_derivatives(const pin::Model& m, pin::Data& d,
                                                          const VectorXd& q, const VectorXd& v,
                                                          const VectorXd& a) {
  pin::computeRNEADerivatives(m, d, q, v, a);
  return d.dtau_dq.data();
}
SOFTRNE_BENCH_NOINLINE const double* pin_aba_derivatives(const pin::Model& m, pin::Data& d,
                                                         const VectorXd& q, const VectorXd& v,
                                                         const VectorXd& tau) {
  pin::computeABADerivatives(m, d, q, v, tau);
  return d.ddq_dq.data();
}

void register_pinocchio(const std::string& prefix, std::shared_ptr<PinocchioFixture> f) {
  const int nq = f->model.nq;
  auto reg = [&](const char* fn, auto body) {
    const std::string name = prefix + "/" + fn;
    bodies()[name] = [f, body](unsigned k) { body(*f, k & (kStates - 1)); };
    benchmark::RegisterBenchmark(name.c_str(), [f, body, nq](benchmark::State& st) {
      unsigned k = 0;
      for (auto _ : st) {
        body(*f, k & (kStates - 1));
        ++k;
      }
      set_counters(st, f->n, nq);
    })->Unit(unit_for(nq > 10 ? 1e5 : 1e3));
  };
  using Fix = PinocchioFixture;
  reg("rnea", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_rnea(x.model, x.data, x.q[k], x.qd[k], x.qdd[k]).data());
  });
  reg("gravity", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_gravity(x.model, x.data, x.q[k]).data());
  });
  reg("bias", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_nle(x.model, x.data, x.q[k], x.qd[k]).data());
  });
  reg("crba", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_crba(x.model, x.data, x.q[k]).data());
  });
  reg("aba", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_aba(x.model, x.data, x.q[k], x.qd[k], x.tau[k]).data());
  });
  // Against softrne's rnea_derivatives / aba_derivatives (analytical recursions in Pinocchio).
  reg("rnea_derivatives", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_rnea_derivatives(x.model, x.data, x.q[k], x.qd[k], x.qdd[k]));
  });
  reg("aba_derivatives", [](Fix& x, unsigned k) {
    benchmark::DoNotOptimize(pin_aba_derivatives(x.model, x.data, x.q[k], x.qd[k], x.tau[k]));
  });
}

/// Before timing anything: the Pinocchio models must give softrne's numbers.
bool pinocchio_agrees(ChainFixture<DynamicChain<double>>& s, PinocchioFixture& p,
                      const std::string& name) {
  double err = 0, scale = 1;
  for (int k = 0; k < kStates; ++k) {
    const VectorXd tau = rnea(s.chain, s.data, s.q[k], s.qd[k], s.qdd[k]);
    pin::rnea(p.model, p.data, p.q[k], p.qd[k], p.qdd[k]);
    err = std::max(err, (tau - p.data.tau).cwiseAbs().maxCoeff());
    scale = std::max(scale, tau.cwiseAbs().maxCoeff());
    const Eigen::MatrixXd M = mass_matrix(s.chain, s.data, s.q[k]);
    pin::crba(p.model, p.data, p.q[k], pin::Convention::LOCAL);
    p.data.M.triangularView<Eigen::StrictlyLower>() =
        p.data.M.transpose().triangularView<Eigen::StrictlyLower>();
    err = std::max(err, (M - p.data.M).cwiseAbs().maxCoeff());
    const VectorXd qdd = forward_dynamics(s.chain, s.data, s.q[k], s.qd[k], s.tau[k]);
    pin::aba(p.model, p.data, p.q[k], p.qd[k], p.tau[k], pin::Convention::LOCAL);
    err = std::max(err, (qdd - p.data.ddq).cwiseAbs().maxCoeff());
    // The derivatives, before their timings are compared.
    rnea_derivatives(s.chain, s.data, s.q[k], s.qd[k], s.qdd[k]);
    pin::computeRNEADerivatives(p.model, p.data, p.q[k], p.qd[k], p.qdd[k]);
    err = std::max(err, (s.data.dtau_dq - p.data.dtau_dq).cwiseAbs().maxCoeff());
    err = std::max(err, (s.data.dtau_dqdot - p.data.dtau_dv).cwiseAbs().maxCoeff());
    aba_derivatives(s.chain, s.data, s.q[k], s.qd[k], s.tau[k]);
    pin::computeABADerivatives(p.model, p.data, p.q[k], p.qd[k], p.tau[k]);
    err = std::max(err, (s.data.dqddot_dq - p.data.ddq_dq).cwiseAbs().maxCoeff());
    err = std::max(err, (s.data.dqddot_dqdot - p.data.ddq_dv).cwiseAbs().maxCoeff());
    // M^-1: Pinocchio fills only the upper triangle of data.Minv.
    Eigen::MatrixXd dMinv = s.data.dqddot_dtau - p.data.Minv;
    dMinv.triangularView<Eigen::StrictlyLower>().setZero();
    err = std::max(err, dMinv.cwiseAbs().maxCoeff());
  }
  std::fprintf(stderr,
               "softrne-bench: check %-28s max |softrne - Pinocchio| / max(1, |tau|) = %.1e\n",
               name.c_str(), err / scale);
  return err / scale < 1e-10;
}
#endif

// ---------------------------------------------------------------------------------------
// CVODE simulation of the bundled arm's test trajectory.

#ifdef SOFTRNE_BENCH_WITH_SIM
/// sim/arm-a-1/<split>[/atol<..>]: simulate_arm from rest at the first measured angles with
/// the recorded pressures, default options (or CVODE's absolute tolerance set to `atol`).
void register_simulation(const std::string& split, double atol) {
  struct Sim {
    ArmDescription desc;
    io::Dataset data;
  };
  std::shared_ptr<Sim> s;
  try {
    const std::string dir = std::string(SOFTRNE_BENCH_DATA_DIR) + "/arm-a-1";
    const io::RobotSpec spec = io::read_robot_json(dir + "/robot.json");
    s = std::make_shared<Sim>(
        Sim{build_arm(spec), io::read_dataset(dir + "/" + split + ".csv", spec, true)});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "softrne-bench: simulation skipped: %s\n", e.what());
    return;
  }
  std::string name = "sim/arm-a-1/" + split;
  if (atol > 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "/atol%g", atol);
    name += buf;
  }
  benchmark::RegisterBenchmark(
      name.c_str(),
      [s, atol](benchmark::State& st) {
        const VectorXd& t = s->data.t;
        const VectorXd q0 = s->data.angles.row(0).transpose();
        const double duration = t(t.size() - 1) - t(0);
        sim::ArmSimulationOptions opt;
        if (atol > 0) opt.cvode.atol = atol;
        sim::ArmSimulation r;
        for (auto _ : st) {
          r = sim::simulate_arm(s->desc, t, s->data.pressures, q0, opt);
          if (!r.ok()) {
            st.SkipWithError(r.result.message.c_str());
            break;
          }
        }
        st.counters["sim_seconds"] = duration;
        st.counters["steps"] = static_cast<double>(r.result.stats.steps);
        st.counters["rhs_evals"] = static_cast<double>(r.result.stats.rhs_evals);
        st.counters["jac_evals"] = static_cast<double>(r.result.stats.jac_evals);
        st.counters["rtol"] = opt.cvode.rtol;
        st.counters["atol"] = opt.cvode.atol;
      })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}
#endif

// ---------------------------------------------------------------------------------------
// Summary: ratios from the medians of this run.

class SummaryReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.error_occurred) continue;
      const std::string name = r.run_name.str();
      const double to_ns = 1e9 / benchmark::GetTimeUnitMultiplier(r.time_unit);
      const double cpu = r.GetAdjustedCPUTime() * to_ns, real = r.GetAdjustedRealTime() * to_ns;
      const auto sec = r.counters.find("sim_seconds");
      const bool plain_or_median = r.run_type != Run::RT_Aggregate || r.aggregate_name == "median";
      if (sec != r.counters.end() && plain_or_median) sim_seconds_[name] = sec->second.value;
      if (r.run_type == Run::RT_Aggregate) {
        if (r.aggregate_name != "median") continue;
        median_[name] = {cpu, real};
      } else if (!median_.count(name) || r.repetitions <= 1) {
        median_[name] = {cpu, real};  // no repetitions: the single run
      }
    }
  }

  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\n=== summary (CPU-time medians of this run; ratio = left / right) ===\n");
    ratio("CC calc / revolute calc (target <= 3)", "calc/cc", "calc/revolute");
    ratio("CC calc / rigid link calc", "calc/cc", "calc/rigid_link");
    for (const char* a : {"rnea", "gravity", "bias", "mass_matrix", "forward_dynamics", "aba"})
      ratio(std::string("arm: dynamic / static ") + a, std::string("arm/dynamic/") + a,
            std::string("arm/static/") + a);
    // Dense (M + Cholesky) against the O(n) articulated-body forward dynamics.
    for (const std::string m : {"arm/static", "arm/dynamic", "rev6/static", "rev6/dynamic",
                                "rev30/dynamic"})
      ratio(m + ": forward_dynamics / aba", m + "/forward_dynamics", m + "/aba");
    // Derivatives (derivatives.hpp) against the RNE itself (target: rnea_derivatives <= 4 x
    // rnea on the paper's arm) and against the forward dynamics.
    for (const std::string m : {"arm/static", "arm/dynamic", "rev6/static", "rev6/dynamic",
                                "rev30/dynamic"}) {
      ratio(m + ": rnea_derivatives / rnea", m + "/rnea_derivatives", m + "/rnea");
      ratio(m + ": aba_derivatives / rnea", m + "/aba_derivatives", m + "/rnea");
      ratio(m + ": aba_derivatives / forward_dynamics", m + "/aba_derivatives",
            m + "/forward_dynamics");
    }
    for (int n : {1, 3, 10, 30, 100, 300})
      ratio("cc/dynamic/" + std::to_string(n) + ": forward_dynamics / aba",
            "cc/dynamic/forward_dynamics/" + std::to_string(n),
            "cc/dynamic/aba/" + std::to_string(n));
    for (const char* model : {"rev6", "rev30"}) {
      const std::string m = model;
      const std::pair<const char*, const char*> pairs[] = {{"rnea", "rnea"},
                                                           {"gravity", "gravity"},
                                                           {"bias", "bias"},
                                                           {"mass_matrix", "crba"},
                                                           {"forward_dynamics", "aba"},
                                                           {"aba", "aba"},
                                                           {"rnea_derivatives", "rnea_derivatives"},
                                                           {"aba_derivatives", "aba_derivatives"}};
      for (const char* impl : {"static", "dynamic"})
        for (const auto& [ours, theirs] : pairs)
          for (const char* pin_impl : {"pinocchio", "pinocchio_unaligned"})
            ratio(m + " softrne " + impl + " " + ours + " / " + pin_impl + " " + theirs,
                  m + "/" + impl + "/" + ours, m + "/" + pin_impl + "/" + theirs);
    }
    // Pinocchio's own derivative / rnea ratio (the issue guessed "about 2-3x for rigid
    // chains"; docs/performance.md, "Derivatives", has the measurement).
    for (const char* model : {"rev6", "rev30"})
      for (const char* pin_impl : {"pinocchio", "pinocchio_unaligned"})
        ratio(std::string(model) + " " + pin_impl + ": rnea_derivatives / rnea",
              std::string(model) + "/" + pin_impl + "/rnea_derivatives",
              std::string(model) + "/" + pin_impl + "/rnea");
    // Scaling of the runtime CC chain: time per CC segment (each with its rigid link).
    for (const char* a : {"rnea", "mass_matrix", "aba"}) {
      double ref = 0;
      bool any = false;
      for (int n : {1, 3, 10, 30, 100, 300, 1000}) {
        const auto it = median_.find("cc/dynamic/" + std::string(a) + "/" + std::to_string(n));
        if (it == median_.end()) continue;
        if (!any) std::printf("%s per CC segment [ns]:", a);
        any = true;
        const double per = it->second.first / n;
        if (n == 10) ref = per;
        std::printf("  n=%d %.4g", n, per);
      }
      if (!any) continue;
      std::printf("\n");
      if (ref > 0) {
        double lo = 1e300, hi = 0;
        for (int n : {10, 30, 100, 300, 1000}) {
          const auto it = median_.find("cc/dynamic/" + std::string(a) + "/" + std::to_string(n));
          if (it == median_.end()) continue;
          lo = std::min(lo, it->second.first / n);
          hi = std::max(hi, it->second.first / n);
        }
        std::printf("  %s per segment, n = 10..1000: max / min = %.3f%s\n", a, hi / lo,
                    std::string(a) == "mass_matrix" ? " (O(n nq): grows ~ n)"
                                                    : " (target <= 1.25)");
      }
    }
    // Simulations: wall-clock time against the simulated duration (the paper's measure).
    for (const auto& [name, times] : median_) {
      if (name.rfind("sim/", 0) != 0) continue;
      const auto d = sim_seconds_.find(name);
      if (d == sim_seconds_.end()) continue;
      std::printf("%-40s %.3f s wall for %.2f s simulated = %.3f %% of real time\n", name.c_str(),
                  times.second * 1e-9, d->second, 100.0 * times.second * 1e-9 / d->second);
    }
  }

 private:
  void ratio(const std::string& label, const std::string& a, const std::string& b) {
    const auto ia = median_.find(a), ib = median_.find(b);
    if (ia == median_.end() || ib == median_.end()) return;
    std::printf("%-62s %8.3f   (%.4g ns / %.4g ns)\n", label.c_str(),
                ia->second.first / ib->second.first, ia->second.first, ib->second.first);
  }
  std::map<std::string, std::pair<double, double>> median_;  // name -> (cpu ns, real ns)
  std::map<std::string, double> sim_seconds_;                // simulated duration
};

int register_all() {
  // (d) single segments
  register_calc("cc", arm_cc(), 1.0);
  {
    Rev r;
    r.axis = Vector3d(0.3, -0.5, 0.8).normalized();
    register_calc("revolute", r, 1.0);
  }
  register_calc("rigid_link", arm_link_12(), 1.0);

  // (a) the paper's arm
  register_chain("arm/static", "", std::make_shared<ChainFixture<StaticArm>>(make_static_arm(), 3),
                 kAll, 400);
  register_chain("arm/dynamic", "",
                 std::make_shared<ChainFixture<DynamicChain<double>>>(make_dynamic_arm(), 3), kAll,
                 400);

  // (b) n CC segments, each followed by a rigid link
  for (int n : {1, 3, 10, 30, 100, 300, 1000}) {
    unsigned which = kRnea | kGravity | kBias | kMassMatrix;
    if (n <= 300) which |= kForwardDynamics;  // the O(nq^3) Cholesky dominates beyond
    which |= kAba;                            // O(n): every n
    register_chain("cc/dynamic", "/" + std::to_string(n),
                   std::make_shared<ChainFixture<DynamicChain<double>>>(make_cc_chain(n), n), which,
                   130.0 * n);
  }

  // (c) revolute chains
  for (int n : {6, 30}) {
    const std::string m = "rev" + std::to_string(n);
    auto dyn = std::make_shared<ChainFixture<DynamicChain<double>>>(make_rev_chain(n), n);
    if (n == 6)
      register_chain(
          m + "/static", "",
          std::make_shared<ChainFixture<StaticRev6>>(to_static<StaticRev6>(dyn->chain), n), kAll,
          40.0 * n);
    register_chain(m + "/dynamic", "", dyn, kAll, 40.0 * n);
#ifdef SOFTRNE_BENCH_WITH_PINOCCHIO
    for (bool unaligned : {false, true}) {
      auto p = std::make_shared<PinocchioFixture>(make_pinocchio_rev_chain(dyn->chain, unaligned),
                                                  *dyn, n);
      const std::string pm = m + (unaligned ? "/pinocchio_unaligned" : "/pinocchio");
      if (!pinocchio_agrees(*dyn, *p, pm)) {
        std::fprintf(stderr, "softrne-bench: %s does not match softrne\n", pm.c_str());
        return 1;
      }
      register_pinocchio(pm, p);
    }
#endif
  }

#ifdef SOFTRNE_BENCH_WITH_SIM
  register_simulation("train", 0);
  register_simulation("test", 0);
  register_simulation("test", 1e-8);  // tight: CVODE atol 1e-8 (reference quality)
#endif
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // --benchmark_format=json|csv on stdout: no console summary (it would corrupt the output).
  bool console = true;
  // --profile=NAME [--profile_calls=N]: call benchmark NAME's body N times (default 1000)
  // outside Google Benchmark's loop and exit; for valgrind --tool=callgrind, whose count of
  // instructions divided by N is the cost of one call (docs/performance.md).
  std::string profile;
  long profile_calls = 1000;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--benchmark_format=", 19) == 0 &&
        std::strcmp(argv[i] + 19, "console") != 0)
      console = false;
    if (std::strncmp(argv[i], "--profile=", 10) == 0)
      profile = argv[i] + 10;
    else if (std::strncmp(argv[i], "--profile_calls=", 16) == 0)
      profile_calls = std::atol(argv[i] + 16);
    else
      argv[kept++] = argv[i];
  }
  argc = kept;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
#ifdef SOFTRNE_BENCH_WITH_PINOCCHIO
  std::fprintf(stderr, "softrne-bench: Pinocchio %s (header-only, same compiler and flags)\n",
               PINOCCHIO_VERSION);
#else
  std::fprintf(stderr, "softrne-bench: Pinocchio not built in (see docs/performance.md)\n");
#endif
  if (register_all() != 0) return 1;
  if (!profile.empty()) {
    const auto it = bodies().find(profile);
    if (it == bodies().end()) {
      std::fprintf(stderr, "softrne-bench: no benchmark body '%s'; one of:\n", profile.c_str());
      for (const auto& b : bodies()) std::fprintf(stderr, "  %s\n", b.first.c_str());
      return 1;
    }
    for (long k = 0; k < profile_calls; ++k) it->second(static_cast<unsigned>(k));
    std::fprintf(stderr, "softrne-bench: %ld calls of %s\n", profile_calls, profile.c_str());
    return 0;
  }
  if (console) {
    SummaryReporter reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
  } else {
    benchmark::RunSpecifiedBenchmarks();
  }
  benchmark::Shutdown();
  return 0;
}
