#pragma once
/// \file
/// \brief Pneumatic constant-curvature (CC) continuum joint, paper section III-A.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "softrne/config.hpp"
#include "softrne/segments/cc_functions.hpp"
#include "softrne/segments/segment_kinematics.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {

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
template <class Scalar_>
struct ConstantCurvatureJoint {
  using Scalar = Scalar_;
  static constexpr int nq = 2;
  static constexpr bool has_body = true;
  static constexpr int max_chambers = 8;
  using Kinematics = SegmentKinematics<Scalar, nq>;
  using Vector2 = Eigen::Matrix<Scalar, 2, 1>;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  /// 2 x K map from chamber pressures to (tau_u, tau_v); at most max_chambers columns, stored
  /// inline (no heap).
  using PressureMap = Eigen::Matrix<Scalar, 2, Eigen::Dynamic, 0, 2, max_chambers>;

  Scalar mass{1};      ///< m, kg
  Scalar height{0.2};  ///< h, arc length, m
  Scalar diameter{0.2};  ///< D, disk diameter, m
  Vector2 stiffness = Vector2::Zero();  ///< diagonal of K_spring, N m/rad
  Vector2 damping = Vector2::Zero();    ///< diagonal of K_d, N m s/rad
  PressureMap pressure_to_torque = four_chamber_map(Scalar(0.06), Scalar(0.03));  ///< K_prs

  /// \brief Eq. 24: four chambers at distance d from the axis with radius delta,
  /// \f$\tau_u = dA(p_0-p_1)\f$, \f$\tau_v = dA(p_2-p_3)\f$, \f$A = \pi\delta^2\f$.
  static PressureMap four_chamber_map(const Scalar& chamber_distance,
                                      const Scalar& chamber_radius) {
    const Scalar dA = chamber_distance * Scalar(M_PI) * chamber_radius * chamber_radius;
    PressureMap K(2, 4);
    K << dA, -dA, Scalar(0), Scalar(0), Scalar(0), Scalar(0), dA, -dA;
    return K;
  }

  int num_inputs() const { return static_cast<int>(pressure_to_torque.cols()); }

  /// \brief Linear spring and damper of eq. 23: \f$-K_{spring} q - K_d \dot q\f$.
  template <class Q, class Qd>
  Vector2 passive_force(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot) const {
    return -(stiffness.cwiseProduct(q) + damping.cwiseProduct(qdot));
  }

  /// \brief Fills kin for configuration q and velocity qdot (both of size 2).
  template <class Q, class Qd>
  void calc(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot,
            Kinematics& kin) const {
    const Scalar u = q(0), v = q(1);
    const Scalar ud = qdot(0), vd = qdot(1);
    const Scalar x = u * u + v * v;  // phi^2
    detail::CCArcFunctions<Scalar> f;
    f.compute(x);
    const auto& g = f.at_x.g;
    const auto& dg = f.at_x.dg;
    const auto& ddg = f.at_x.ddg;

    const Vector3 w(u, v, Scalar(0));        // rotation vector of the distal frame
    const Vector3 w_perp(v, -u, Scalar(0));  // in-plane direction the arc bends towards
    const Vector3 wd(ud, vd, Scalar(0));
    const Vector3 wd_perp(vd, -ud, Scalar(0));
    const Vector3 ez = Vector3::UnitZ();
    const Scalar s = u * ud + v * vd;     // (1/2) d(phi^2)/dt
    const Scalar wd2 = ud * ud + vd * vd;

    // Eq. 2 is Rodrigues' formula for the rotation vector w = (u, v, 0).
    const Matrix3 W = skew(w);
    const Matrix3 W2 = W * W;
    kin.R_base_distal = Matrix3::Identity() + g[1] * W + g[2] * W2;

    // Eqs. 3-4 and 9: r = h (A(x) w_perp + B(x) e_z) with (A, B) = (g2, g1) for the distal
    // end and (g3, g2) for the centre of mass. Their Jacobians and Jdot*qdot follow from
    // d/dq_j A(x) = 2 A'(x) q_j.
    const Scalar h = height;
    auto position = [&](int a, int b, Eigen::Ref<Vector3> r, Eigen::Ref<Eigen::Matrix<Scalar, 3, 2>> J,
                        Eigen::Ref<Vector3> Jdot_qdot) {
      r = h * (g[a] * w_perp + g[b] * ez);
      const Vector3 common = Scalar(2) * (dg[a] * w_perp + dg[b] * ez);
      J.col(0) = h * (common * u + g[a] * Vector3(0, -1, 0).template cast<Scalar>());
      J.col(1) = h * (common * v + g[a] * Vector3(1, 0, 0).template cast<Scalar>());
      Jdot_qdot = h * ((Scalar(4) * ddg[a] * s * s + Scalar(2) * dg[a] * wd2) * w_perp +
                       Scalar(4) * dg[a] * s * wd_perp +
                       (Scalar(4) * ddg[b] * s * s + Scalar(2) * dg[b] * wd2) * ez);
    };
    Eigen::Matrix<Scalar, 3, 2> Je_lin;
    Vector3 Jdot_e_lin;
    position(2, 1, kin.r_base_distal, Je_lin, Jdot_e_lin);
    position(3, 2, kin.r_base_com, kin.J_com, kin.Jdot_qdot_com);

    // Angular velocity omega = J_l(w) wdot with the SO(3) left Jacobian
    // J_l = I + g2 [w]x + g3 [w]x^2 (the angular rows of eq. 6).
    const Matrix3 Jl = Matrix3::Identity() + g[2] * W + g[3] * W2;
    kin.J_distal.template topRows<3>() = Je_lin;
    kin.J_distal.template bottomRows<3>() = Jl.template leftCols<2>();
    // Eq. 8 applied to wdot: (dJ_l/dt) wdot = 2s g2' w x wd + 2s g3' w x (w x wd)
    //                                        + g3 wd x (w x wd).
    const Vector3 w_x_wd = w.cross(wd);
    kin.Jdot_qdot_distal.template head<3>() = Jdot_e_lin;
    kin.Jdot_qdot_distal.template tail<3>() = Scalar(2) * s * dg[2] * w_x_wd +
                                              Scalar(2) * s * dg[3] * w.cross(w_x_wd) +
                                              g[3] * wd.cross(w_x_wd);

    calc_inertia(f, u, v, w_perp, kin);
    kin.inertia_rate = kin.dinertia_dq[0] * ud + kin.dinertia_dq[1] * vd;
  }

  /// \brief Generalised forces of the chamber pressures (eq. 24 or a custom layout).
  template <class P>
  Vector2 actuation(const Eigen::MatrixBase<P>& pressures) const {
    return pressure_to_torque * pressures;
  }

  template <class NewScalar>
  ConstantCurvatureJoint<NewScalar> cast() const {
    ConstantCurvatureJoint<NewScalar> c;
    c.mass = NewScalar(mass);
    c.height = NewScalar(height);
    c.diameter = NewScalar(diameter);
    c.stiffness = stiffness.template cast<NewScalar>();
    c.damping = damping.template cast<NewScalar>();
    c.pressure_to_torque = pressure_to_torque.template cast<NewScalar>();
    return c;
  }

 private:
  /// Eqs. 19-22 in closed form. In the base frame, about the centre of mass,
  /// \f$I^b = s_0 \mathbf 1 + a_w w_\perp w_\perp^T + a_{wz}(w_\perp e_z^T + e_z w_\perp^T)
  /// + a_z e_z e_z^T\f$: the disks' own inertia (eq. 20) averaged over the arc, plus the
  /// parallel-axis terms of eqs. 21-22 integrated analytically, minus those of the centre of
  /// mass. Then \f$I^i = R^T I^b R\f$ (eq. 19).
  void calc_inertia(const detail::CCArcFunctions<Scalar>& f, const Scalar& u, const Scalar& v,
                    const Vector3& w_perp, Kinematics& kin) const {
    const auto& g = f.at_x.g;
    const auto& dg = f.at_x.dg;
    const Scalar x = u * u + v * v;
    const Scalar G2 = f.at_4x.g[2], G3 = f.at_4x.g[3];
    const Scalar dG2 = Scalar(4) * f.at_4x.dg[2], dG3 = Scalar(4) * f.at_4x.dg[3];  // d/dx
    const Scalar md = mass * diameter * diameter / Scalar(16);
    const Scalar mh = mass * height * height;

    const Scalar s0 = md + Scalar(2) * mh * g[3] - mh * (x * g[3] * g[3] + g[2] * g[2]);
    const Scalar a_w = Scalar(2) * md * G3 - Scalar(2) * mh * f.d3 + mh * g[3] * g[3];
    const Scalar a_wz = md * G2 - mh * f.d2 + mh * g[3] * g[2];
    const Scalar a_z = md * (Scalar(1) - Scalar(2) * x * G3) - Scalar(2) * mh * G3 + mh * g[2] * g[2];

    const Scalar ds0 = Scalar(2) * mh * dg[3] -
                       mh * (g[3] * g[3] + Scalar(2) * x * g[3] * dg[3] + Scalar(2) * g[2] * dg[2]);
    const Scalar da_w = Scalar(2) * md * dG3 - Scalar(2) * mh * f.dd3 + Scalar(2) * mh * g[3] * dg[3];
    const Scalar da_wz = md * dG2 - mh * f.dd2 + mh * (dg[3] * g[2] + g[3] * dg[2]);
    const Scalar da_z = md * (-Scalar(2) * G3 - Scalar(2) * x * dG3) - Scalar(2) * mh * dG3 +
                        Scalar(2) * mh * g[2] * dg[2];

    const Vector3 ez = Vector3::UnitZ();
    const Matrix3 WW = w_perp * w_perp.transpose();
    const Matrix3 WZ = w_perp * ez.transpose() + ez * w_perp.transpose();
    const Matrix3 ZZ = ez * ez.transpose();
    const Matrix3 Ib = s0 * Matrix3::Identity() + a_w * WW + a_wz * WZ + a_z * ZZ;
    const Matrix3 dIb_dx = ds0 * Matrix3::Identity() + da_w * WW + da_wz * WZ + da_z * ZZ;

    const Matrix3& R = kin.R_base_distal;
    kin.inertia_com = R.transpose() * Ib * R;

    // dI^i/dq_j = R^T (dI^b/dq_j + I^b [w_j]x - [w_j]x I^b) R with w_j the j-th angular
    // Jacobian column, since dR/dq_j = [w_j]x R.
    const Vector3 dwperp[2] = {Vector3(Scalar(0), Scalar(-1), Scalar(0)),
                               Vector3(Scalar(1), Scalar(0), Scalar(0))};
    const Scalar qj[2] = {u, v};
    for (int j = 0; j < 2; ++j) {
      const Matrix3 dIb = Scalar(2) * qj[j] * dIb_dx +
                          a_w * (dwperp[j] * w_perp.transpose() + w_perp * dwperp[j].transpose()) +
                          a_wz * (dwperp[j] * ez.transpose() + ez * dwperp[j].transpose());
      const Matrix3 Wj = skew(kin.J_distal.template bottomRows<3>().col(j));
      kin.dinertia_dq[static_cast<std::size_t>(j)] =
          R.transpose() * (dIb + Ib * Wj - Wj * Ib) * R;
    }
  }
};

}  // namespace softrne
