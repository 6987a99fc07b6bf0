#pragma once
/// \file
/// \brief Pneumatic constant-curvature (CC) continuum joint, paper section III-A.

#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "softrne/config.hpp"
#include "softrne/segments/cc_functions.hpp"
#include "softrne/segments/segment_kinematics.hpp"
#include "softrne/segments/sub_bodies.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {

/// \brief Inertia model of a CC joint: the paper's one lumped body (eqs. 9, 14, 18-19). The
/// default.
struct LumpedInertia {
  static constexpr int num_points = 0;  ///< no quadrature disks: one lumped body
};

/// \brief Default number of Gauss-Legendre points of DistributedInertia: the smallest with
/// relative error below 1e-8 in M, C qdot and G against the continuum for bending angles up to
/// 2 rad (tests/core/test_distributed_inertia.cpp, docs/model.md).
inline constexpr int kDefaultGaussPoints = 6;

/// \brief Inertia model of a CC joint: the exact continuum of thin disks, integrated along the
/// arc with an NG-point Gauss-Legendre rule. Disk g at arc fraction s_g has the CC pose of
/// \f$(s_g u, s_g v)\f$ with height \f$s_g h\f$, mass \f$w_g m\f$ and the eq. 20 inertia;
/// the algorithms treat the disks as rigid sub-bodies of the segment.
template <int NG = kDefaultGaussPoints>
struct DistributedInertia {
  static_assert(NG >= 1, "DistributedInertia needs at least one point");
  static constexpr int num_points = NG;  ///< quadrature disks along the arc
};

namespace detail {

/// \brief NG-point Gauss-Legendre rule on [0, 1] (weights sum to 1), in long double.
template <int NG>
struct GaussLegendre01 {
  std::array<long double, static_cast<std::size_t>(NG)> nodes{}, weights{};
  /// P_NG(x) and its derivative, by the three-term recurrence.
  static void legendre(long double x, long double& p, long double& dp) {
    long double p0 = 1, p1 = x;
    for (int k = 2; k <= NG; ++k) {
      const long double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    if (NG == 1) p0 = 1;
    p = p1;
    dp = NG * (x * p1 - p0) / (x * x - 1);
  }
  GaussLegendre01() {
    const long double pi = 3.141592653589793238462643383279502884L;
    for (int i = 0; i < NG; ++i) {
      // Newton on P_NG from the usual asymptotic guess; nodes in decreasing order of x.
      long double x = std::cos(pi * (static_cast<long double>(i) + 0.75L) /
                               (static_cast<long double>(NG) + 0.5L));
      long double p = 0, dp = 1;
      for (int it = 0; it < 100; ++it) {
        legendre(x, p, dp);
        const long double dx = p / dp;
        x -= dx;
        if (std::fabs(dx) < 1e-19L) break;
      }
      legendre(x, p, dp);  // derivative at the converged node, for the weight
      const auto k = static_cast<std::size_t>(NG - 1 - i);  // increasing s
      nodes[k] = (1 + x) / 2;
      weights[k] = 1 / ((1 - x * x) * dp * dp);  // 2 / ((1 - x^2) P'^2), halved for [0, 1]
    }
  }
  static const GaussLegendre01& get() {
    static const GaussLegendre01 rule;
    return rule;
  }
};

}  // namespace detail

/// \brief A constant-curvature joint with coordinates q = (u, v): the rotation of the distal
/// end about the base x and y axes, with its mass spread uniformly along the arc of length h
/// as thin disks of diameter D (the paper's lumped model: one body whose centre of mass moves
/// with r_c(q), eq. 9, and which rotates with the distal frame, eqs. 18-19).
///
/// Everything is written with the entire functions \f$g_k(u^2+v^2)\f$ of cc_functions.hpp, so
/// every quantity and its derivatives are exact and smooth at q = 0 and for any bending angle
/// \f$\phi = \sqrt{u^2+v^2}\f$. Beyond \f$\phi = \pi\f$ the arc curls past a half circle: the
/// formulas remain exact for that geometry (nothing is singular there), though a real joint
/// seldom gets there.
///
/// Which centre-of-mass Jacobian: the centre of mass of a bending arc is not a point fixed in
/// the distal frame, so its velocity is \f$\dot r_c = (\partial r_c/\partial q)\dot q\f$ and not
/// the distal Jacobian shifted to r_c. The model uses \f$\partial r_c/\partial q\f$ because it is
/// the one that makes the Newton-Euler forces equal the Euler-Lagrange equations of the
/// lumped energy (tested against a Lagrangian derivation).
///
/// \tparam InertiaModel LumpedInertia (the paper's model, the default) or
/// DistributedInertia<NG> (the continuum of thin disks by NG-point Gauss-Legendre quadrature:
/// each disk rotates with its own part of the arc; the RNE treats the disks as sub-bodies).
/// Kinematics of the distal frame are the same for both.
template <class Scalar_, class InertiaModel = LumpedInertia>
struct ConstantCurvatureJoint {
  using Scalar = Scalar_;       ///< double, long double or an AutoDiff type
  using Inertia = InertiaModel;  ///< LumpedInertia or DistributedInertia<NG>
  static constexpr int nq = 2;   ///< the bending angles u, v (eq. 1)
  static constexpr bool has_body = true;  ///< it carries mass
  static constexpr int max_chambers = 8;  ///< most pressure inputs (columns of K_prs)

  /// Quadrature disks (0: lumped).
  static constexpr int num_points = InertiaModel::num_points;
  static constexpr bool distributed = num_points > 0;  ///< the disks are sub-bodies

  /// What calc() fills: one lumped body, or the disks as sub-bodies.
  using Kinematics = std::conditional_t<distributed, MultiBodyKinematics<Scalar, nq, num_points>,
                                        SegmentKinematics<Scalar, nq>>;
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;  ///< a 2-vector (q, qdot, forces)
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;  ///< a 3-vector
  using Vector6 = Eigen::Matrix<Scalar, 6, 1>;  ///< a 6-vector (linear; angular)
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;  ///< a 3x3 matrix

  /// 2 x K map from chamber pressures to (tau_u, tau_v); at most max_chambers columns, stored
  /// inline (no heap).
  using PressureMap = Eigen::Matrix<Scalar, 2, Eigen::Dynamic, 0, 2, max_chambers>;

  Scalar mass{1};                       ///< m, kg
  Scalar height{0.2};                   ///< h, arc length, m
  Scalar diameter{0.2};                 ///< D, disk diameter, m
  Vector2 stiffness = Vector2::Zero();  ///< diagonal of K_spring, N m/rad
  Vector2 damping = Vector2::Zero();    ///< diagonal of K_d, N m s/rad
  PressureMap pressure_to_torque = four_chamber_map(Scalar(0.06), Scalar(0.03));  ///< K_prs

  /// \brief Eq. 24: four chambers at distance d from the axis with radius delta,
  /// \f$\tau_u = dA(p_0-p_1)\f$, \f$\tau_v = dA(p_2-p_3)\f$, \f$A = \pi\delta^2\f$.
  /// \param[in] chamber_distance d, from the joint's axis to a chamber's centre, m.
  /// \param[in] chamber_radius delta, a chamber's radius, m.
  /// \return K_prs (2 x 4), N m/Pa.
  static PressureMap four_chamber_map(const Scalar& chamber_distance,
                                      const Scalar& chamber_radius) {
    const Scalar dA = chamber_distance * Scalar(M_PI) * chamber_radius * chamber_radius;
    PressureMap K(2, 4);
    K << dA, -dA, Scalar(0), Scalar(0), Scalar(0), Scalar(0), dA, -dA;
    return K;
  }

  /// \return The number of chambers (pressure inputs), the columns of pressure_to_torque.
  int num_inputs() const { return static_cast<int>(pressure_to_torque.cols()); }

  /// \brief Linear spring and damper of eq. 23: \f$-K_{spring} q - K_d \dot q\f$.
  /// \param[in] q The joint's (u, v), rad.
  /// \param[in] qdot Their rates, rad/s.
  /// \return The generalised force (tau_u, tau_v), N m.
  template <class Q, class Qd>
  Vector2 passive_force(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot) const {
    return -(stiffness.cwiseProduct(q) + damping.cwiseProduct(qdot));
  }

  /// \brief Fills kin for configuration q and velocity qdot (both of size 2).
  ///
  /// Written out per component: with w = (u, v, 0) every product of [w]x with itself or
  /// with e_z has a closed form, so no 3x3 matrix product is formed.
  ///
  /// Eqs. 1-9 (rotation, distal position, Jacobian, its rate, centre of mass) and the
  /// inertia: lumped, eq. 19 with eqs. 20-22 in closed form; or DistributedInertia's
  /// quadrature disks, each with the inertia of eq. 20.
  /// \param[in] q (u, v), rad.
  /// \param[in] qdot (u', v'), rad/s (for the Jacobian rates and the inertia rate).
  /// \param[out] kin The segment's kinematics.
  template <class Q, class Qd>
  void calc(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
            Kinematics& kin) const {
    const Scalar u = q(0), v = q(1);
    const Scalar ud = qdot(0), vd = qdot(1);
    if constexpr (distributed) {
      detail::CCFunctions<Scalar> f;
      f.compute(u * u + v * v);
      Vector3 unused_r;
      Eigen::Matrix<Scalar, 3, nq> unused_J;
      arc_kinematics<false>(f, u, v, ud, vd, height, kin.R_base_distal, kin.r_base_distal,
                            kin.J_distal, kin.Jdot_qdot_distal, unused_r, unused_J, unused_r);
      calc_disks(u, v, ud, vd, kin);
    } else {
      const Scalar x = u * u + v * v;  // phi^2
      detail::CCArcFunctions<Scalar> f;
      f.compute(x);
      arc_kinematics<true>(f.at_x, u, v, ud, vd, height, kin.R_base_distal, kin.r_base_distal,
                           kin.J_distal, kin.Jdot_qdot_distal, kin.r_base_com, kin.J_com,
                           kin.Jdot_qdot_com);
      calc_inertia(f, u, v, ud, vd, kin);
    }
  }

  /// \brief calc() without the inertia (lumped model): the pose, Jacobians and their rates
  /// only; inertia_com, dinertia_dq and inertia_rate are left as they are. The derivatives
  /// (algorithms/derivatives.hpp) run this in AutoDiff and take the inertia's derivatives from
  /// calc() and inertia_hessian_times() instead.
  /// \param[in] q (u, v), rad.
  /// \param[in] qdot (u', v'), rad/s (for the Jacobian rates).
  /// \param[out] kin The segment's kinematics, but for the inertia fields.
  template <class Q, class Qd>
  void calc_motion(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
                   Kinematics& kin) const {
    static_assert(!distributed, "calc_motion: the lumped model only");
    const Scalar u = q(0), v = q(1);
    detail::CCFunctions<Scalar> f;  // the same functions at x as calc's CCArcFunctions
    f.compute(u * u + v * v);
    arc_kinematics<true>(f, u, v, qdot(0), qdot(1), height, kin.R_base_distal,
                         kin.r_base_distal, kin.J_distal, kin.Jdot_qdot_distal, kin.r_base_com,
                         kin.J_com, kin.Jdot_qdot_com);
  }

  /// \brief The second derivatives of the lumped inertia about the centre of mass (distal
  /// axes, eq. 19) applied to a vector w: out[i][j] = \f$(\partial^2 I^i/\partial q_i\partial
  /// q_j)\,w\f$. (The derivatives' tangent steps need them only against the distal angular
  /// velocity, so no 3 x 3 matrix is formed.)
  ///
  /// With \f$\Phi(X) = R^T X R\f$ and \f$\partial_i R = R[w'_i]_\times\f$ (w'_i: the right
  /// Jacobian's column, inertia_terms), \f$\partial_i\Phi(X) = \Phi(\partial_i X) + C(\Phi(X),
  /// w'_i)\f$ with \f$C(A, w) = A[w]_\times - [w]_\times A\f$, so \f$C(A, w)y = A(w\times y) -
  /// w\times Ay\f$. Applied twice to \f$I^b\f$:
  /// \f[ \partial_i\partial_j I^i = T_{ij} + C(T_j, w'_i) + C(T_i, w'_j)
  ///     + C(C(I^i, w'_i), w'_j) + C(I^i, \partial_i w'_j), \f]
  /// \f$T_j = \Phi(\partial_j I^b) = 2q_j D + a_w S^p_j + a_{wz} S^e_j\f$ (calc_inertia's
  /// terms, \f$S^p_j = \mathrm{sym}(p_j, p)\f$, \f$S^e_j = \mathrm{sym}(p_j, e)\f$,
  /// \f$\mathrm{sym}(a, b) = ab^T + ba^T\f$) and \f$T_{ij} = \Phi(\partial_i\partial_j I^b) =
  /// 2\delta_{ij}D + 4q_iq_j D_2 + 2q_j(a_w' S^p_i + a_{wz}' S^e_i) + 2q_i(a_w' S^p_j + a_{wz}'
  /// S^e_j) + a_w\,\mathrm{sym}(p_i, p_j)\f$, with \f$D_2\f$ the coefficients' second
  /// derivatives in x on the same basis. Tested against calc() in AutoDiff, at phi = 0 and
  /// across the series switches (tests/core/test_derivatives.cpp, KinematicsTangents.*).
  /// \param[in] q (u, v), rad.
  /// \param[in] kin calc()'s output at q (its R_base_distal, inertia_com are read).
  /// \param[in] w The vector (distal axes).
  /// \param[out] out The 2 x 2 symmetric block of vectors.
  template <class Q>
  void inertia_hessian_times(const Eigen::MatrixBase<Q>& q, const Kinematics& kin,
                             const Vector3& w,
                             std::array<std::array<Vector3, nq>, nq>& out) const {
    static_assert(!distributed, "inertia_hessian_times: the lumped model only");
    const Scalar u = q(0), v = q(1);
    const Scalar x = u * u + v * v;
    detail::CCArcFunctions<Scalar> f;
    f.compute(x);
    const InertiaTerms t = inertia_terms(f, u, v, kin.R_base_distal);
    const auto& g = f.at_x.g;
    const auto& dg = f.at_x.dg;
    const auto& ddg = f.at_x.ddg;
    Scalar ddG[2], ddd[2];  // d^2/dx^2 of g_2, g_3 at 4x; d_2'', d_3''
    f.second_derivatives(x, ddG, ddd);
    const Scalar dG3 = Scalar(4) * f.at_4x.dg[3];
    const Scalar md = mass * diameter * diameter / Scalar(16);
    const Scalar mh = mass * height * height;
    // The second derivatives in x of (s0, a_w, a_wz, a_z) (inertia_terms' first ones, again).
    const Scalar dds0 =
        Scalar(2) * mh * ddg[3] -
        mh * (Scalar(4) * g[3] * dg[3] + Scalar(2) * x * (dg[3] * dg[3] + g[3] * ddg[3]) +
              Scalar(2) * (dg[2] * dg[2] + g[2] * ddg[2]));
    const Scalar dda_w = Scalar(2) * md * ddG[1] - Scalar(2) * mh * ddd[1] +
                         Scalar(2) * mh * (dg[3] * dg[3] + g[3] * ddg[3]);
    const Scalar dda_wz = md * ddG[0] - mh * ddd[0] +
                          mh * (ddg[3] * g[2] + Scalar(2) * dg[3] * dg[2] + g[3] * ddg[2]);
    const Scalar dda_z = -Scalar(2) * md * (Scalar(2) * dG3 + x * ddG[1]) -
                         Scalar(2) * mh * ddG[1] + Scalar(2) * mh * (dg[2] * dg[2] + g[2] * ddg[2]);

    const Vector3& p = t.p;
    const Vector3& e = t.e;
    // (s 1 + a_w p p^T + a_wz (p e^T + e p^T) + a_z e e^T) y: D (first derivatives of the
    // coefficients) and D_2 (second) on calc_inertia's basis, times a vector.
    auto basis_times = [&](const Scalar& s, const Scalar& a_w, const Scalar& a_wz,
                           const Scalar& a_z, const Vector3& y) -> Vector3 {
      const Scalar py = p.dot(y), ey = e.dot(y);
      return s * y + (a_w * py + a_wz * ey) * p + (a_wz * py + a_z * ey) * e;
    };
    auto D_times = [&](const Vector3& y) {
      return basis_times(t.ds0, t.da_w, t.da_wz, t.da_z, y);
    };
    const Vector3 D2w = basis_times(dds0, dda_w, dda_wz, dda_z, w);
    // The vectors through which S^p_j, S^e_j act: a_w S^p_j + a_wz S^e_j = sym(p_j, m) and
    // a_w' S^p_j + a_wz' S^e_j = sym(p_j, n).
    const Vector3 m = t.a_w * p + t.a_wz * e, n = t.da_w * p + t.da_wz * e;
    const Scalar nw = n.dot(w), dpw[2] = {t.dp[0].dot(w), t.dp[1].dot(w)};
    const Scalar qj[2] = {u, v};
    // T_j y = 2 q_j D y + p_j (m.y) + m (p_j.y).
    auto T_times = [&](int j, const Vector3& y, const Vector3& Dy) -> Vector3 {
      return Scalar(2) * qj[j] * Dy + m.dot(y) * t.dp[j] + t.dp[j].dot(y) * m;
    };
    const Matrix3& I = kin.inertia_com;  // I^i, calc's
    const Vector3 Iw = I * w, Dw = D_times(w);
    Vector3 c[2], Ic[2], Dc[2], CIw[2];  // c_i = w'_i x w, I c_i, D c_i, C(I, w'_i) w
    for (int i = 0; i < 2; ++i) {
      c[i] = cross3(t.wr[i], w);
      Ic[i] = I * c[i];
      Dc[i] = D_times(c[i]);
      CIw[i] = Ic[i] - cross3(t.wr[i], Iw);
    }
    Vector3 Tw[2], Tc[2][2];  // T_j w, T_j c_i
    for (int j = 0; j < 2; ++j) {
      Tw[j] = T_times(j, w, Dw);
      for (int i = 0; i < 2; ++i) Tc[j][i] = T_times(j, c[i], Dc[i]);
    }
    const Scalar uu = u * u, vv = v * v, uv = u * v;
    for (int i = 0; i < 2; ++i) {
      const Scalar c3 = Scalar(2) * qj[i] * dg[3], c2 = Scalar(2) * qj[i] * dg[2];
      // d_i of the monomials v^2, u v, v, u^2, u.
      const Scalar dvv = i == 1 ? Scalar(2) * v : Scalar(0), duv = i == 0 ? v : u;
      const Scalar dv = Scalar(i == 1 ? 1 : 0), duu = i == 0 ? Scalar(2) * u : Scalar(0);
      const Scalar du = Scalar(i == 0 ? 1 : 0);
      const Vector3 dwr[2] = {
          Vector3(-c3 * vv - g[3] * dvv, c3 * uv + g[3] * duv, c2 * v + g[2] * dv),
          Vector3(c3 * uv + g[3] * duv, -c3 * uu - g[3] * duu, -c2 * u - g[2] * du)};
      for (int j = i; j < 2; ++j) {
        // T_ij w
        Vector3 h = Scalar(4) * qj[i] * qj[j] * D2w +
                    Scalar(2) * qj[j] * (nw * t.dp[i] + dpw[i] * n) +
                    Scalar(2) * qj[i] * (nw * t.dp[j] + dpw[j] * n) +
                    t.a_w * (dpw[j] * t.dp[i] + dpw[i] * t.dp[j]);
        if (i == j) h += Scalar(2) * Dw;
        // C(T_j, w'_i) w + C(T_i, w'_j) w
        h += Tc[j][i] - cross3(t.wr[i], Tw[j]) + Tc[i][j] - cross3(t.wr[j], Tw[i]);
        // C(C(I, w'_i), w'_j) w, with C(I, w'_i) y = I (w'_i x y) - w'_i x I y
        const Vector3 wc = cross3(t.wr[i], c[j]);
        h += I * wc - cross3(t.wr[i], Ic[j]) - cross3(t.wr[j], CIw[i]);
        // C(I, d_i w'_j) w
        h += I * cross3(dwr[j], w) - cross3(dwr[j], Iw);
        out[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = h;
        if (j != i) out[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] = h;
      }
    }
  }

  /// \brief Generalised forces of the chamber pressures (eq. 24 or a custom layout).
  /// \param[in] pressures One pressure per chamber (num_inputs()), Pa.
  /// \return \f$K_{prs}p\f$ = (tau_u, tau_v), N m.
  template <class P>
  Vector2 actuation(const Eigen::MatrixBase<P>& pressures) const {
    return pressure_to_torque * pressures;
  }

  /// \brief The same joint in another scalar type.
  /// \tparam NewScalar The new scalar type.
  /// \return A copy with every constant converted.
  template <class NewScalar>
  ConstantCurvatureJoint<NewScalar, InertiaModel> cast() const {
    ConstantCurvatureJoint<NewScalar, InertiaModel> c;
    c.mass = NewScalar(mass);
    c.height = NewScalar(height);
    c.diameter = NewScalar(diameter);
    c.stiffness = stiffness.template cast<NewScalar>();
    c.damping = damping.template cast<NewScalar>();
    c.pressure_to_torque = pressure_to_torque.template cast<NewScalar>();
    return c;
  }

  /// \brief The same joint (parameters) with another inertia model.
  /// \tparam NewModel LumpedInertia or DistributedInertia<NG>.
  /// \return A copy with the same constants.
  template <class NewModel>
  ConstantCurvatureJoint<Scalar, NewModel> with_inertia() const {
    ConstantCurvatureJoint<Scalar, NewModel> c;
    c.mass = mass;
    c.height = height;
    c.diameter = diameter;
    c.stiffness = stiffness;
    c.damping = damping;
    c.pressure_to_torque = pressure_to_torque;
    return c;
  }

  /// \brief Pose, Jacobians and their rates of the distal frame of an arc of height h at
  /// (u, v) with velocity (ud, vd), from the functions f at \f$u^2+v^2\f$; with kWithCom also
  /// the centre of mass of the arc (eq. 9). Used for the segment and for each quadrature disk.
  /// \param[in] f The CC functions of \f$\phi^2 = u^2+v^2\f$ (eqs. 1-5).
  /// \param[in] u Bending angle about x, rad.
  /// \param[in] v Bending angle about y, rad.
  /// \param[in] ud Rate of u.
  /// \param[in] vd Rate of v.
  /// \param[in] height The arc's height (length) h, m.
  /// \param[out] R Distal orientation (eq. 2).
  /// \param[out] r_e Distal position (eq. 4).
  /// \param[out] J_e Distal geometric Jacobian (eqs. 5-6).
  /// \param[out] Jdot_qdot_e \f$\dot J\dot q\f$ (eq. 8).
  /// \param[out] r_c Centre of mass (eq. 9; kWithCom only).
  /// \param[out] J_c \f$\partial r_c/\partial q\f$ (kWithCom only).
  /// \param[out] Jdot_qdot_c Its rate times qdot (kWithCom only).
  template <bool kWithCom, class JE, class JC>
  static void arc_kinematics(const detail::CCFunctions<Scalar>& f, const Scalar& u,
                             const Scalar& v, const Scalar& ud, const Scalar& vd,
                             const Scalar& height, Matrix3& R, Vector3& r_e, JE& J_e,
                             Vector6& Jdot_qdot_e, Vector3& r_c, JC& J_c,
                             Vector3& Jdot_qdot_c) {
    const Scalar uu = u * u, vv = v * v, uv = u * v;
    const Scalar x = uu + vv;  // phi^2
    const auto& g = f.g;
    const auto& dg = f.dg;
    const auto& ddg = f.ddg;

    // Eq. 2 is Rodrigues' formula for the rotation vector w = (u, v, 0):
    // R = I + g1 [w]x + g2 [w]x^2 with [w]x^2 = w w^T - x I.
    R(0, 0) = Scalar(1) - g[2] * vv;
    R(0, 1) = g[2] * uv;
    R(0, 2) = g[1] * v;
    R(1, 0) = g[2] * uv;
    R(1, 1) = Scalar(1) - g[2] * uu;
    R(1, 2) = -g[1] * u;
    R(2, 0) = -g[1] * v;
    R(2, 1) = g[1] * u;
    R(2, 2) = Scalar(1) - g[2] * x;

    // Eqs. 3-4 and 9: r = h (A(x) w_perp + B(x) e_z), w_perp = (v, -u, 0), with (A, B) =
    // (g2, g1) for the distal end and (g3, g2) for the centre of mass. Their Jacobians and
    // Jdot*qdot follow from d/dq_j A(x) = 2 A'(x) q_j; s = (1/2) d(phi^2)/dt.
    const Scalar h = height;
    const Scalar s = u * ud + v * vd;
    const Scalar wd2 = ud * ud + vd * vd;
    const Scalar ss4 = Scalar(4) * s * s;
    auto position = [&](int a, int b, Vector3& r, auto&& J, auto&& Jdot_qdot) {
      r = Vector3(h * g[a] * v, -h * g[a] * u, h * g[b]);
      const Scalar ca = Scalar(2) * h * dg[a], cb = Scalar(2) * h * dg[b];
      J(0, 0) = ca * uv;
      J(1, 0) = -ca * uu - h * g[a];
      J(2, 0) = cb * u;
      J(0, 1) = ca * vv + h * g[a];
      J(1, 1) = -ca * uv;
      J(2, 1) = cb * v;
      // h ((4 A'' s^2 + 2 A' |wd|^2) w_perp + 4 A' s wd_perp + (4 B'' s^2 + 2 B' |wd|^2) e_z)
      const Scalar A = h * (ss4 * ddg[a] + Scalar(2) * dg[a] * wd2);
      const Scalar Bs = Scalar(2) * ca * s;
      Jdot_qdot(0) = A * v + Bs * vd;
      Jdot_qdot(1) = -A * u - Bs * ud;
      Jdot_qdot(2) = h * (ss4 * ddg[b] + Scalar(2) * dg[b] * wd2);
    };
    position(2, 1, r_e, J_e, Jdot_qdot_e);
    if constexpr (kWithCom) position(3, 2, r_c, J_c, Jdot_qdot_c);

    // Angular velocity omega = J_l(w) wdot with the SO(3) left Jacobian
    // J_l = I + g2 [w]x + g3 [w]x^2 (the angular rows of eq. 6); only its first two columns.
    J_e(3, 0) = Scalar(1) - g[3] * vv;
    J_e(4, 0) = g[3] * uv;
    J_e(5, 0) = -g[2] * v;
    J_e(3, 1) = g[3] * uv;
    J_e(4, 1) = Scalar(1) - g[3] * uu;
    J_e(5, 1) = g[2] * u;
    // Eq. 8 applied to wdot: (dJ_l/dt) wdot = 2s g2' w x wd + 2s g3' w x (w x wd)
    //                                        + g3 wd x (w x wd),
    // with w x wd = c e_z, w x e_z = w_perp, wd x e_z = wd_perp.
    const Scalar c = u * vd - v * ud;
    const Scalar t3 = Scalar(2) * s * dg[3] * c, g3c = g[3] * c;
    Jdot_qdot_e(3) = t3 * v + g3c * vd;
    Jdot_qdot_e(4) = -t3 * u - g3c * ud;
    Jdot_qdot_e(5) = Scalar(2) * s * dg[2] * c;
  }

 private:
  /// \brief The quadrature disks of the distributed model. Disk g at arc fraction s has the
  /// pose of an arc of height s h at (s u, s v); its position is \f$p(s q; s h)\f$, so its
  /// Jacobians are s times those of that arc's distal frame, and their rates along qdot are
  /// that arc's \f$\dot J\dot q\f$ at the velocity s qdot (exact). Mass \f$w_g m\f$, inertia
  /// about its centre (eq. 20) \f$w_g m D^2/16\,(\mathbf 1 + n n^T)\f$ with n its normal (the
  /// third column of its rotation): constant in the disk's frame, so no inertia-rate terms.
  void calc_disks(const Scalar& u, const Scalar& v, const Scalar& ud, const Scalar& vd,
                  Kinematics& kin) const {
    using Real = typename Eigen::NumTraits<Scalar>::Real;
    const auto& rule = detail::GaussLegendre01<num_points>::get();
    const Scalar a_disk = diameter * diameter / Scalar(16);
    kin.r_base_com.setZero();
    kin.J_com.setZero();
    kin.Jdot_qdot_com.setZero();
    Eigen::Matrix<Scalar, 6, nq> J;
    Vector6 Jdq;
    Vector3 unused_r;
    Eigen::Matrix<Scalar, 3, nq> unused_J;
    detail::CCFunctions<Scalar> f;
    for (std::size_t k = 0; k < static_cast<std::size_t>(num_points); ++k) {
      const Scalar s(static_cast<Real>(rule.nodes[k]));
      const Scalar w(static_cast<Real>(rule.weights[k]));
      const Scalar us = s * u, vs = s * v;
      f.compute(us * us + vs * vs);
      auto& b = kin.sub_bodies[k];
      arc_kinematics<false>(f, us, vs, s * ud, s * vd, s * height, b.R_base_body, b.r_base_body,
                            J, Jdq, unused_r, unused_J, unused_r);
      b.mass = w * mass;
      b.J_v = s * J.template topRows<3>();
      b.J_w = s * J.template bottomRows<3>();
      b.Jdot_qdot_v = Jdq.template head<3>();
      b.Jdot_qdot_w = Jdq.template tail<3>();
      const Vector3 n = b.R_base_body.col(2);
      const Scalar a = b.mass * a_disk;
      b.inertia.noalias() = a * (n * n.transpose());
      b.inertia.diagonal().array() += a;
      kin.r_base_com += w * b.r_base_body;
      kin.J_com += w * b.J_v;
      kin.Jdot_qdot_com += w * b.Jdot_qdot_v;
    }
  }

  /// Eqs. 19-22 in closed form. In the base frame, about the centre of mass,
  /// \f$I^b = s_0 \mathbf 1 + a_w w_\perp w_\perp^T + a_{wz}(w_\perp e_z^T + e_z w_\perp^T)
  /// + a_z e_z e_z^T\f$: the disks' own inertia (eq. 20) averaged over the arc, plus the
  /// parallel-axis terms of eqs. 21-22 integrated analytically, minus those of the centre of
  /// mass. Then \f$I^i = R^T I^b R\f$ (eq. 19), formed directly in the distal frame from
  /// \f$p = R^T w_\perp = (g_0 v, -g_0 u, g_1 x)\f$ and \f$e = R^T e_z = (-g_1 v, g_1 u, g_0)\f$
  /// (R turns the plane of \f$w_\perp\f$ and \f$e_z\f$ about w, which it leaves fixed).
  /// Also fills dinertia_dq and inertia_rate.
  void calc_inertia(const detail::CCArcFunctions<Scalar>& f, const Scalar& u, const Scalar& v,
                    const Scalar& ud, const Scalar& vd, Kinematics& kin) const {
    const InertiaTerms t = inertia_terms(f, u, v, kin.R_base_distal);
    // Symmetric matrices as their 6 entries (xx, yy, zz, xy, xz, yz).
    const Sym PP = outer(t.p), EE = outer(t.e), PE = sym(t.p, t.e);
    Sym I, D;  // I^i, and R^T (dI^b/dx) R
    for (int k = 0; k < 6; ++k) {
      I[k] = t.a_w * PP[k] + t.a_wz * PE[k] + t.a_z * EE[k];
      D[k] = t.da_w * PP[k] + t.da_wz * PE[k] + t.da_z * EE[k];
    }
    for (int k = 0; k < 3; ++k) {
      I[k] += t.s0;
      D[k] += t.ds0;
    }
    to_matrix(I, kin.inertia_com);
    // dI^i/dq_j = R^T (dI^b/dq_j) R + I^i [w'_j]x - [w'_j]x I^i, since dR/dq_j = [w_j]x R with
    // w_j the j-th angular Jacobian column and w'_j = R^T w_j the j-th column of the right
    // Jacobian J_r = R^T J_l = I - g2 [w]x + g3 [w]x^2; R^T dw_perp/dq_j = R^T (-e_y), R^T e_x.
    const Scalar qj[2] = {u, v};
    Sym rate;
    for (int j = 0; j < 2; ++j) {
      const Sym C = commutator(I, t.wr[j]), Sp = sym(t.dp[j], t.p), Se = sym(t.dp[j], t.e);
      const Scalar two_q = Scalar(2) * qj[j];
      Sym dI;
      for (int k = 0; k < 6; ++k) dI[k] = two_q * D[k] + t.a_w * Sp[k] + t.a_wz * Se[k] + C[k];
      to_matrix(dI, kin.dinertia_dq[static_cast<std::size_t>(j)]);
      if (j == 0)
        for (int k = 0; k < 6; ++k) rate[k] = dI[k] * ud;
      else
        for (int k = 0; k < 6; ++k) rate[k] += dI[k] * vd;
    }
    to_matrix(rate, kin.inertia_rate);
  }

  /// What calc_inertia and inertia_hessian_times share: the coefficients of
  /// \f$I^b = s_0\mathbf 1 + a_w w_\perp w_\perp^T + a_{wz}(w_\perp e_z^T + e_z w_\perp^T) + a_z
  /// e_z e_z^T\f$ and their derivatives in x, the vectors p, e (calc_inertia's comment), p_j =
  /// R^T dw_perp/dq_j, and the right Jacobian's columns w'_j. (inertia_terms is always inlined:
  /// out of line it cost rnea 0.8 % more instructions on the paper's arm.)
  struct InertiaTerms {
    Scalar s0, a_w, a_wz, a_z, ds0, da_w, da_wz, da_z;
    Vector3 p, e, dp[2], wr[2];
  };
  EIGEN_ALWAYS_INLINE InertiaTerms inertia_terms(const detail::CCArcFunctions<Scalar>& f,
                                                 const Scalar& u, const Scalar& v,
                                                 const Matrix3& R) const {
    const auto& g = f.at_x.g;
    const auto& dg = f.at_x.dg;
    const Scalar x = u * u + v * v;
    const Scalar G2 = f.at_4x.g[2], G3 = f.at_4x.g[3];
    const Scalar dG2 = Scalar(4) * f.at_4x.dg[2], dG3 = Scalar(4) * f.at_4x.dg[3];  // d/dx
    const Scalar md = mass * diameter * diameter / Scalar(16);
    const Scalar mh = mass * height * height;
    InertiaTerms t;
    t.s0 = md + Scalar(2) * mh * g[3] - mh * (x * g[3] * g[3] + g[2] * g[2]);
    t.a_w = Scalar(2) * md * G3 - Scalar(2) * mh * f.d3 + mh * g[3] * g[3];
    t.a_wz = md * G2 - mh * f.d2 + mh * g[3] * g[2];
    t.a_z = md * (Scalar(1) - Scalar(2) * x * G3) - Scalar(2) * mh * G3 + mh * g[2] * g[2];
    t.ds0 = Scalar(2) * mh * dg[3] -
            mh * (g[3] * g[3] + Scalar(2) * x * g[3] * dg[3] + Scalar(2) * g[2] * dg[2]);
    t.da_w = Scalar(2) * md * dG3 - Scalar(2) * mh * f.dd3 + Scalar(2) * mh * g[3] * dg[3];
    t.da_wz = md * dG2 - mh * f.dd2 + mh * (dg[3] * g[2] + g[3] * dg[2]);
    t.da_z = md * (-Scalar(2) * G3 - Scalar(2) * x * dG3) - Scalar(2) * mh * dG3 +
             Scalar(2) * mh * g[2] * dg[2];
    const Scalar c0 = R(2, 2);  // = g0 = cos(phi), as R computes it
    t.p = Vector3(c0 * v, -c0 * u, g[1] * x);
    t.e = R.row(2).transpose();
    t.dp[0] = -R.row(1).transpose();
    t.dp[1] = R.row(0).transpose();
    t.wr[0] = Vector3(Scalar(1) - g[3] * v * v, g[3] * u * v, g[2] * v);
    t.wr[1] = Vector3(g[3] * u * v, Scalar(1) - g[3] * u * u, -g[2] * u);
    return t;
  }

  /// A symmetric 3x3 matrix as (xx, yy, zz, xy, xz, yz).
  using Sym = std::array<Scalar, 6>;
  static Sym outer(const Vector3& a) {  // a a^T
    return {a(0) * a(0), a(1) * a(1), a(2) * a(2), a(0) * a(1), a(0) * a(2), a(1) * a(2)};
  }
  static Sym sym(const Vector3& a, const Vector3& b) {  // a b^T + b a^T
    return {Scalar(2) * a(0) * b(0),   Scalar(2) * a(1) * b(1),   Scalar(2) * a(2) * b(2),
            a(0) * b(1) + a(1) * b(0), a(0) * b(2) + a(2) * b(0), a(1) * b(2) + a(2) * b(1)};
  }
  /// \f$I[w]_\times - [w]_\times I\f$ for symmetric I (symmetric: \f$A + A^T\f$, \f$A =
  /// I[w]_\times\f$).
  static Sym commutator(const Sym& I, const Vector3& w) {
    const Scalar &xx = I[0], &yy = I[1], &zz = I[2], &xy = I[3], &xz = I[4], &yz = I[5];
    return {Scalar(2) * (w(2) * xy - w(1) * xz),      Scalar(2) * (w(0) * yz - w(2) * xy),
            Scalar(2) * (w(1) * xz - w(0) * yz),      w(2) * (yy - xx) + w(0) * xz - w(1) * yz,
            w(1) * (xx - zz) - w(0) * xy + w(2) * yz, w(0) * (zz - yy) + w(1) * xy - w(2) * xz};
  }
  static void to_matrix(const Sym& s, Matrix3& m) {
    m(0, 0) = s[0];
    m(1, 1) = s[1];
    m(2, 2) = s[2];
    m(0, 1) = m(1, 0) = s[3];
    m(0, 2) = m(2, 0) = s[4];
    m(1, 2) = m(2, 1) = s[5];
  }
};

}  // namespace softrne
