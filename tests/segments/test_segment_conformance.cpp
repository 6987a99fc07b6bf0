// One conformance suite for every segment type (as Sophus and manif run one suite per Lie
// group): the types are those of the runtime chain's variant (AnySegment, segment_list.hpp),
// so a new segment type is tested here as soon as it is listed there (and fails to compile
// until it has an Example below). For each type, on random states and, for the CC joints, at
// phi = 0 exactly and on both sides of every series switch (cc_functions.hpp):
//   - its Jacobians, their rates, dI/dq and dI/dt (and those of its sub-bodies) are the
//     derivatives of its pose and inertia: Eigen AutoDiff (1e-12 relative) and central
//     finite differences (1e-7);
//   - it casts to long double and to an AutoDiff scalar, which compile and agree with double;
//   - calc allocates nothing (the guard's positive control is at the end of the file).
// Type-specific references (the arc integrated as an ODE, disk sums, closed forms) stay in
// tests/core/test_cc_joint.cpp and test_distributed_inertia.cpp.
#include "../eigen_malloc_guard.hpp"  // first: before anything includes Eigen
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "../core/autodiff_reference.hpp"
#include "../core/support.hpp"
#include "softrne/softrne.hpp"

namespace {

using namespace softrne;
using Eigen::Matrix3d;
using Eigen::Vector3d;

// ---------------------------------------------------------------------------------------
// The types, and one example of each.

template <class Variant>
struct AsTestTypes;
template <class... Segments>
struct AsTestTypes<std::variant<Segments...>> {
  using type = ::testing::Types<Segments...>;
};
using SegmentTypes = AsTestTypes<AnySegment<double>>::type;

/// An example of each segment type, and the bending angles where its formulas switch.
template <class Segment>
struct Example;

template <class Inertia>
struct Example<ConstantCurvatureJoint<double, Inertia>> {
  static ConstantCurvatureJoint<double, Inertia> make() {
    return softrne_test::paper_cc<double>(0.8, 0.2, 0.15).template with_inertia<Inertia>();
  }
  /// phi^2 < kCCSeriesSwitch takes the series of g_6, g_7; the lumped inertia's d_k(x) switch
  /// at kCCDiffSwitch and need g_k at 4x (so also at a quarter of each switch); disk g of the
  /// distributed model bends by s_g phi, so it switches at phi = sqrt(kCCSeriesSwitch) / s_g.
  static std::vector<double> switch_angles() {
    const double sw = std::sqrt(detail::kCCSeriesSwitch), swd = std::sqrt(detail::kCCDiffSwitch);
    std::vector<double> a = {sw, swd, sw / 2, swd / 2};
    if constexpr (Inertia::num_points > 0) {
      for (long double s : detail::GaussLegendre01<Inertia::num_points>::get().nodes)
        if (sw / static_cast<double>(s) < 4.0) a.push_back(sw / static_cast<double>(s));
    }
    return a;
  }
};

template <>
struct Example<RigidLink<double>> {
  static RigidLink<double> make() { return softrne_test::paper_link<double>(1.5, 0.15); }
};

template <>
struct Example<RevoluteJoint<double>> {
  static RevoluteJoint<double> make() { return softrne_test::revolute<double>(1, 0.2, -0.4); }
};

template <class Segment>
using VectorQ = Eigen::Matrix<double, Segment::nq, 1>;

template <class Segment>
struct State {
  VectorQ<Segment> q, qd;
};

/// 100 random states (|q_i| <= 2.5, |qd_i| <= 3); for the CC joints also phi = 0, tiny
/// angles, pi, and the two doubles next to each switch angle, in three directions.
template <class Segment>
std::vector<State<Segment>> states(unsigned seed) {
  constexpr int n = Segment::nq;
  std::mt19937 rng(seed);
  std::vector<State<Segment>> s;
  for (int i = 0; i < 100; ++i)
    s.push_back({softrne_test::random_vector(rng, n, 2.5), softrne_test::random_vector(rng, n, 3.0)});
  if constexpr (n == 2) {
    std::vector<double> phis = {0.0, 1e-12, 1e-8, 1e-4, 1e-3, 0.1, 3.0, M_PI - 1e-9, M_PI};
    for (double a : Example<Segment>::switch_angles()) {
      phis.push_back(a);
      phis.push_back(std::nextafter(a, 0.0));
      phis.push_back(std::nextafter(a, 10.0));
    }
    for (double phi : phis)
      for (double dir : {0.0, 0.7, 2.0})
        s.push_back({Eigen::Vector2d(phi * std::cos(dir), phi * std::sin(dir)), Eigen::Vector2d(0.8, -1.3)});
  }
  return s;
}

template <class Segment>
typename Segment::Kinematics calc(const Segment& seg, const VectorQ<Segment>& q, const VectorQ<Segment>& qd) {
  typename Segment::Kinematics k;
  seg.calc(q, qd, k);
  return k;
}

/// Axial vector of the skew part of A (A = dR R^T: the angular velocity).
Vector3d vee(const Matrix3d& A) {
  return 0.5 * Vector3d(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
}

/// |a - b| / max(floor, |b|).
template <class A, class B>
double rel(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b, double floor = 1.0) {
  return (a - b).norm() / std::max(floor, b.norm());
}

template <class Segment>
class SegmentConformance : public ::testing::Test {};

struct SegmentNames {
  template <class Segment>
  static std::string GetName(int) {
    if constexpr (std::is_same_v<Segment, ConstantCurvatureJoint<double>>) return "CCJointLumped";
    if constexpr (std::is_same_v<Segment, DistributedCCJoint<double>>) return "CCJointDistributed";
    if constexpr (std::is_same_v<Segment, RigidLink<double>>) return "RigidLink";
    if constexpr (std::is_same_v<Segment, RevoluteJoint<double>>) return "RevoluteJoint";
    return "Segment";
  }
};
TYPED_TEST_SUITE(SegmentConformance, SegmentTypes, SegmentNames);

// ---------------------------------------------------------------------------------------
// Derivatives against AutoDiff: one pass with nq + 1 directions, d/dq_i (i < nq) and d/dt
// along q + t qd (direction nq: the rates), with qd constant.

template <class ADT, class M>
auto values(const M& a) {
  return a.unaryExpr([](const ADT& x) { return x.value(); }).eval();
}
template <class ADT, class M>
auto derivatives(const M& a, int direction) {
  return a.unaryExpr([direction](const ADT& x) { return x.derivatives()(direction); }).eval();
}

TYPED_TEST(SegmentConformance, DerivativesMatchAutoDiff) {
  using Segment = TypeParam;
  constexpr int n = Segment::nq;
  using ADT = softrne_test::ADN<n + 1>;
  const Segment seg = Example<Segment>::make();
  const auto seg_ad = seg.template cast<ADT>();
  double worst = 0;
  for (const auto& st : states<Segment>(4)) {
    const VectorQ<Segment>&q = st.q, &qd = st.qd;  // named, for the lambda below
    const auto k = calc(seg, q, qd);
    Eigen::Matrix<ADT, n, 1> qa, qda;
    for (int i = 0; i < n; ++i) {
      qa(i).value() = q(i);
      qa(i).derivatives().setZero();
      qa(i).derivatives()(i) = 1.0;
      qa(i).derivatives()(n) = qd(i);
      qda(i).value() = qd(i);
      qda(i).derivatives().setZero();
    }
    typename decltype(seg_ad)::Kinematics ka;
    seg_ad.calc(qa, qda, ka);
    const Matrix3d R = values<ADT>(ka.R_base_distal);
    auto expect = [&](double e, double tol, const char* what) {
      EXPECT_LT(e, tol) << what << " at q = " << q.transpose() << ", qd = " << qd.transpose();
      worst = std::max(worst, e);
    };
    // The AutoDiff scalar's values are the double ones.
    expect(rel(R, k.R_base_distal), 1e-14, "R_base_distal (AutoDiff value)");
    expect(rel(values<ADT>(ka.r_base_distal), k.r_base_distal), 1e-14, "r_base_distal (AutoDiff value)");
    expect(rel(values<ADT>(ka.r_base_com), k.r_base_com), 1e-14, "r_base_com (AutoDiff value)");
    expect(rel(values<ADT>(ka.inertia_com), k.inertia_com), 1e-14, "inertia_com (AutoDiff value)");
    // Jacobians and dI/dq.
    Eigen::Matrix<double, 6, n> J;
    Eigen::Matrix<double, 3, n> Jc;
    if constexpr (n > 0) {  // (a link has no coordinates: empty Jacobians)
      for (int i = 0; i < n; ++i) {
        J.col(i) << derivatives<ADT>(ka.r_base_distal, i), vee(derivatives<ADT>(ka.R_base_distal, i) * R.transpose());
        Jc.col(i) = derivatives<ADT>(ka.r_base_com, i);
        const Matrix3d dI = derivatives<ADT>(ka.inertia_com, i);
        expect(rel(k.dinertia_dq[static_cast<std::size_t>(i)], dI, std::max(1e-300, k.inertia_com.norm())), 1e-12,
               "dinertia_dq");
      }
    }
    expect(rel(k.J_distal, J), 1e-12, "J_distal");
    expect(rel(k.J_com, Jc), 1e-12, "J_com");
    // Rates: d/dt [J(q + t qd) qd] and d/dt I(q + t qd).
    const double rate_scale = std::max(1.0, qd.squaredNorm());
    expect(rel(k.Jdot_qdot_distal, derivatives<ADT>(ka.J_distal * qda, n), rate_scale), 1e-12, "Jdot_qdot_distal");
    expect(rel(k.Jdot_qdot_com, derivatives<ADT>(ka.J_com * qda, n), rate_scale), 1e-12, "Jdot_qdot_com");
    expect(rel(k.inertia_rate, derivatives<ADT>(ka.inertia_com, n),
               std::max(1e-300, k.inertia_com.norm() * std::max(1.0, qd.norm()))),
           1e-12, "inertia_rate");
    // Sub-bodies: J_v, J_w and their rates.
    if constexpr (detail::num_sub_bodies<Segment> > 0) {
      for (std::size_t b = 0; b < k.sub_bodies.size(); ++b) {
        const auto& B = k.sub_bodies[b];
        const auto& Ba = ka.sub_bodies[b];
        const Matrix3d Rb = values<ADT>(Ba.R_base_body);
        expect(rel(Rb, B.R_base_body), 1e-14, "sub-body R_base_body (AutoDiff value)");
        for (int i = 0; i < n; ++i) {
          expect(rel(B.J_v.col(i), derivatives<ADT>(Ba.r_base_body, i)), 1e-12, "sub-body J_v");
          expect(rel(B.J_w.col(i), vee(derivatives<ADT>(Ba.R_base_body, i) * Rb.transpose())), 1e-12,
                 "sub-body J_w");
        }
        expect(rel(B.Jdot_qdot_v, derivatives<ADT>(Ba.J_v * qda, n), rate_scale), 1e-12, "sub-body Jdot_qdot_v");
        expect(rel(B.Jdot_qdot_w, derivatives<ADT>(Ba.J_w * qda, n), rate_scale), 1e-12, "sub-body Jdot_qdot_w");
      }
    }
  }
  std::printf("[ info ] worst relative error vs AutoDiff: %.2e\n", worst);
}

// ---------------------------------------------------------------------------------------
// Central finite differences (no AutoDiff): J qd, the rates and dI/dt along qd.
TYPED_TEST(SegmentConformance, DerivativesMatchCentralDifferences) {
  using Segment = TypeParam;
  using VQ = VectorQ<Segment>;
  const Segment seg = Example<Segment>::make();
  const VQ zero = VQ::Zero();
  const double eps = 1e-6;
  for (const auto& [q, qd] : states<Segment>(5)) {
    const auto k = calc(seg, q, qd);
    const auto kp = calc(seg, VQ(q + eps * qd), zero), km = calc(seg, VQ(q - eps * qd), zero);
    const Vector3d v_fd = (kp.r_base_distal - km.r_base_distal) / (2 * eps);
    const Vector3d w_fd = vee((kp.R_base_distal - km.R_base_distal) / (2 * eps) * k.R_base_distal.transpose());
    const Vector3d vc_fd = (kp.r_base_com - km.r_base_com) / (2 * eps);
    EXPECT_LT((k.J_distal.template topRows<3>() * qd - v_fd).norm(), 1e-7 * std::max(1.0, v_fd.norm()));
    EXPECT_LT((k.J_distal.template bottomRows<3>() * qd - w_fd).norm(), 1e-7 * std::max(1.0, w_fd.norm()));
    EXPECT_LT((k.J_com * qd - vc_fd).norm(), 1e-7 * std::max(1.0, vc_fd.norm()));
    // d/dt (J qd) at fixed qd equals Jdot qd.
    const auto kp2 = calc(seg, VQ(q + eps * qd), qd), km2 = calc(seg, VQ(q - eps * qd), qd);
    const Eigen::Matrix<double, 6, 1> dJ = (kp2.J_distal * qd - km2.J_distal * qd) / (2 * eps);
    EXPECT_LT((k.Jdot_qdot_distal - dJ).norm(), 1e-7 * std::max(1.0, dJ.norm()));
    const Vector3d dJc = (kp2.J_com * qd - km2.J_com * qd) / (2 * eps);
    EXPECT_LT((k.Jdot_qdot_com - dJc).norm(), 1e-7 * std::max(1.0, dJc.norm()));
    const Matrix3d dI = (kp.inertia_com - km.inertia_com) / (2 * eps);
    EXPECT_LT((k.inertia_rate - dI).norm(), 1e-7 * std::max(1e-3, dI.norm()));
    if constexpr (detail::num_sub_bodies<Segment> > 0) {
      for (std::size_t b = 0; b < k.sub_bodies.size(); ++b) {
        const auto &B = k.sub_bodies[b], &Bp = kp2.sub_bodies[b], &Bm = km2.sub_bodies[b];
        const Vector3d vb_fd = (Bp.r_base_body - Bm.r_base_body) / (2 * eps);
        EXPECT_LT((B.J_v * qd - vb_fd).norm(), 1e-7 * std::max(1.0, vb_fd.norm()));
        const Vector3d wb_fd = vee((Bp.R_base_body - Bm.R_base_body) / (2 * eps) * B.R_base_body.transpose());
        EXPECT_LT((B.J_w * qd - wb_fd).norm(), 1e-7 * std::max(1.0, wb_fd.norm()));
        const Vector3d dJv = (Bp.J_v * qd - Bm.J_v * qd) / (2 * eps);
        EXPECT_LT((B.Jdot_qdot_v - dJv).norm(), 1e-7 * std::max(1.0, dJv.norm()));
        const Vector3d dJw = (Bp.J_w * qd - Bm.J_w * qd) / (2 * eps);
        EXPECT_LT((B.Jdot_qdot_w - dJw).norm(), 1e-7 * std::max(1.0, dJw.norm()));
      }
    }
  }
}

// ---------------------------------------------------------------------------------------
// Scalar casts: long double agrees with double, and the round trip double -> long double ->
// double gives the same segment (the AutoDiff scalar is compared in DerivativesMatchAutoDiff).
TYPED_TEST(SegmentConformance, LongDoubleAgreesWithDouble) {
  using Segment = TypeParam;
  const Segment seg = Example<Segment>::make();
  const auto seg_l = seg.template cast<long double>();
  const Segment back = seg_l.template cast<double>();
  for (const auto& [q, qd] : states<Segment>(6)) {
    const auto k = calc(seg, q, qd);
    typename decltype(seg_l)::Kinematics kl;
    seg_l.calc(q.template cast<long double>(), qd.template cast<long double>(), kl);
    const double rate_scale = std::max(1.0, qd.squaredNorm());
    EXPECT_LT(rel(k.R_base_distal, kl.R_base_distal.template cast<double>()), 1e-14);
    EXPECT_LT(rel(k.r_base_distal, kl.r_base_distal.template cast<double>()), 1e-14);
    EXPECT_LT(rel(k.r_base_com, kl.r_base_com.template cast<double>()), 1e-14);
    EXPECT_LT(rel(k.J_distal, kl.J_distal.template cast<double>()), 1e-14);
    EXPECT_LT(rel(k.J_com, kl.J_com.template cast<double>()), 1e-14);
    EXPECT_LT(rel(k.inertia_com, kl.inertia_com.template cast<double>()), 1e-15);
    EXPECT_LT(rel(k.Jdot_qdot_distal, kl.Jdot_qdot_distal.template cast<double>(), rate_scale), 1e-14);
    EXPECT_LT(rel(k.Jdot_qdot_com, kl.Jdot_qdot_com.template cast<double>(), rate_scale), 1e-14);
    const auto kb = calc(back, q, qd);
    EXPECT_EQ(kb.R_base_distal, k.R_base_distal);
    EXPECT_EQ(kb.r_base_com, k.r_base_com);
    EXPECT_EQ(kb.J_distal, k.J_distal);
    EXPECT_EQ(kb.inertia_com, k.inertia_com);
    EXPECT_EQ(back.mass, seg.mass);
  }
}

// ---------------------------------------------------------------------------------------
// The placement shortcuts a type declares (identity_rotation, zero_translation; the passes
// then skip the product or the shift, spatial/frame_placement.hpp) hold exactly on every
// state; and the two types that should declare one are seen to (a renamed flag would make
// the shortcut vanish silently).
static_assert(detail::has_identity_rotation<RigidLink<double>>::value);
static_assert(detail::has_zero_translation<RevoluteJoint<double>>::value);
static_assert(!detail::has_identity_rotation<ConstantCurvatureJoint<double>>::value);
static_assert(!detail::has_zero_translation<DistributedCCJoint<double>>::value);

TYPED_TEST(SegmentConformance, DeclaredPlacementShortcutsHold) {
  using Segment = TypeParam;
  const Segment seg = Example<Segment>::make();
  for (const auto& [q, qd] : states<Segment>(8)) {
    const auto k = calc(seg, q, qd);
    if constexpr (detail::has_identity_rotation<Segment>::value) {
      EXPECT_EQ(k.R_base_distal, Matrix3d::Identity());
    }
    if constexpr (detail::has_zero_translation<Segment>::value) {
      EXPECT_EQ(k.r_base_distal, Vector3d::Zero());
      if constexpr (Segment::nq > 0) {
        EXPECT_TRUE((k.J_distal.template topRows<3>().array() == 0.0).all());
        EXPECT_TRUE((k.Jdot_qdot_distal.template head<3>().array() == 0.0).all());
      }
    }
  }
}

// A revolute joint about exactly x, y or z says so (RevoluteKinematics::coordinate_axis, the
// placements' fast path, spatial/axis_rotation.hpp) and writes R with the exact zeros and one
// that path assumes; R is Eigen's AngleAxis to rounding. Any other axis (-z, z off by 1e-150,
// a random one) says -1.
TEST(RevoluteJointAxis, CoordinateAxesGiveTheExactStructure) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> angle(-4.0, 4.0);
  RevoluteJoint<double> r;
  RevoluteJoint<double>::Kinematics k;
  for (int axis = 0; axis < 3; ++axis) {
    r.axis = Vector3d::Unit(axis);
    for (int s = 0; s < 10; ++s) {
      const double q = s == 0 ? 0.0 : angle(rng);
      r.calc(Eigen::Matrix<double, 1, 1>(q), Eigen::Matrix<double, 1, 1>(0.0), k);
      ASSERT_EQ(k.coordinate_axis, axis);
      const Matrix3d R = Eigen::AngleAxisd(q, r.axis).toRotationMatrix();
      EXPECT_LT((k.R_base_distal - R).cwiseAbs().maxCoeff(), 1e-15) << "axis " << axis;
      EXPECT_EQ(k.R_base_distal(axis, axis), 1.0);
      for (int i = 0; i < 3; ++i)
        if (i != axis) {
          EXPECT_EQ(k.R_base_distal(axis, i), 0.0);
          EXPECT_EQ(k.R_base_distal(i, axis), 0.0);
        }
      EXPECT_EQ(k.J_distal, (Eigen::Matrix<double, 6, 1>() << 0, 0, 0, r.axis).finished());
    }
  }
  const Vector3d others[] = {-Vector3d::UnitZ(), Vector3d(1e-150, 0.0, 1.0),
                             Vector3d(0.3, -0.2, 1.0).normalized()};
  for (const Vector3d& a : others) {
    r.axis = a;
    const double q = angle(rng);
    r.calc(Eigen::Matrix<double, 1, 1>(q), Eigen::Matrix<double, 1, 1>(0.0), k);
    EXPECT_EQ(k.coordinate_axis, -1) << a.transpose();
    EXPECT_LT((k.R_base_distal - Eigen::AngleAxisd(q, a).toRotationMatrix()).cwiseAbs().maxCoeff(),
              1e-15);
  }
}

// ---------------------------------------------------------------------------------------
TYPED_TEST(SegmentConformance, CalcDoesNotAllocate) {
  using Segment = TypeParam;
  const Segment seg = Example<Segment>::make();
  const auto s = states<Segment>(7);
  typename Segment::Kinematics k;
  const long eigen_failures_before = softrne_test::eigen_assert_failures;
  Eigen::internal::set_is_malloc_allowed(false);
  for (const auto& [q, qd] : s) seg.calc(q, qd, k);
  Eigen::internal::set_is_malloc_allowed(true);
  EXPECT_EQ(softrne_test::eigen_assert_failures, eigen_failures_before) << "heap allocation where forbidden";
}

}  // namespace
