#pragma once
/// \file
/// \brief O(n) forward dynamics (paper eq. 23) by an articulated-body recursion generalised to
/// multi-coordinate, configuration-dependent segments with bodies of their own.
///
/// ## What is solved
/// Eq. 23 is \f$M(q)\ddot q = \tau - b\f$ with \f$b = C(q,\dot q)\dot q + G(q)\f$. One RNE
/// (sections III-B, III-C) at \f$\ddot q = 0\f$ gives b, including every velocity-product
/// term, gravity and the rate of the configuration-dependent inertia (InertiaRate). What is
/// left, \f$M\ddot q = \tau - b\f$, is the motion of the same chain from rest without gravity:
/// every acceleration is linear in \f$\ddot q\f$, so the articulated-body recursion needs no
/// bias accelerations at all.
///
/// ## Notation (per segment i, everything in its base frame, about its base origin O)
/// Spatial motion \f$a = (a_O;\ \alpha)\f$ (linear acceleration of the point at O; at rest
/// spatial and classical accelerations agree), wrench \f$w = (f;\ n_O)\f$. Moving the reference
/// point to the distal origin \f$r_e\f$ (eq. 4): motion
/// \f$X a = (a_O + \alpha\times r_e;\ \alpha)\f$, \f$X = [1, -[r_e]_\times; 0, 1]\f$; a wrench
/// \f$w_e\f$ about \f$r_e\f$ is \f$X^T w_e = (f;\ n_e + r_e\times f)\f$ about O. The segment
/// moves its distal frame by \f$J = J_{distal}\f$ (eqs. 5-7): with the base frame's motion
/// \f$a_B\f$, the distal frame's is \f$a_e = X a_B + J\ddot q_i\f$ (eqs. 11-15 at rest).
///
/// ## Backward sweep (tip to base)
/// Let \f$I^A_e, p^A_e\f$ be the articulated inertia and force of everything beyond the distal
/// frame: the wrench it needs from the distal frame is \f$w_e = I^A_e a_e + p^A_e\f$ (for the
/// tip, zero). Rotated into base axes (\f$\mathrm{diag}(R,R)\f$, \f$R = R^{i-1}_i\f$, eq. 2) and
/// moved to O: \f$I^A_O = X^T I^A_e X\f$, \f$p^A_O = X^T p^A_e\f$. With
/// \f$S_e = X^{-1}J\f$ (column k: \f$(J_{v,k} + r_e\times J_{w,k};\ J_{w,k})\f$, the velocity of
/// the distal frame's point at O), \f$X^T w_e = I^A_O(a_B + S_e\ddot q_i) + p^A_O\f$.
///
/// The own body is not rigid with the distal frame (its centre of mass follows eq. 9), so it
/// has its own motion subspace; own_inertia.hpp gives its blocks (spatial, coupling = I_b S_b,
/// joint = S_b^T I_b S_b). The generalised forces of segment i are the power-conjugate
/// projections used by the RNE's backward step (the children's wrench through J, the body
/// through J_com and J_w):
/// \f[\tau_i - b_i = J^T w_e + \text{coupling}^T a_B + \text{joint}\,\ddot q_i
///   = U^T a_B + D\ddot q_i + S_e^T p^A_O,\f]
/// \f[U = \text{coupling} + I^A_O S_e,\quad D = \text{joint} + S_e^T I^A_O S_e.\f]
/// Hence \f$\ddot q_i = D^{-1}(u - U^T a_B)\f$ with \f$u = \tau_i - b_i - S_e^T p^A_O\f$, and
/// the wrench at O, \f$w_B = X^Tw_e + \text{spatial}\,a_B + \text{coupling}\,\ddot q_i\f$,
/// becomes \f$I^A_B a_B + p^A_B\f$ with
/// \f[I^A_B = I^A_O + \text{spatial} - U D^{-1}U^T,\qquad p^A_B = p^A_O + U D^{-1}u,\f]
/// which is what segment i-1 sees at its distal frame. For a rigid link (nq = 0) only
/// \f$I^A_B = I^A_O + \text{spatial}\f$ remains; a revolute joint has no body and
/// \f$r_e = 0\f$. If the own body moved rigidly with the distal frame (S_b = S_e) this is
/// Featherstone's ABA with \f$I^A = I^A_O + \text{spatial}\f$ before projection.
///
/// ## Forward sweep (base to tip)
/// \f$a_B = 0\f$ at the chain's base (gravity is in b); per segment \f$\ddot q_i = D^{-1}(u -
/// U^T a_B)\f$, then \f$a_e = X a_B + J\ddot q_i\f$ rotated by \f$R^T\f$ into the distal frame,
/// the next segment's base frame.
///
/// Cost: one kinematics evaluation and one RNE (as `bias`), then per segment a handful of 3x3
/// products: O(n). The per-segment U, D^{-1}, u live in data.articulated (no allocation). D
/// is inverted in closed form (1x1, 2x2) or by a written-out Cholesky (larger nq), never by
/// Eigen's triangular solvers, which skip exactly-zero right-hand sides and would drop
/// AutoDiff derivative parts (see forward_dynamics.hpp).

#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Core>

#include "softrne/algorithms/bias.hpp"
#include "softrne/algorithms/cholesky.hpp"
#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/mass_matrix.hpp"
#include "softrne/algorithms/own_inertia.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/algorithms/rnea_steps.hpp"
#include "softrne/config.hpp"
#include "softrne/segments/segment_list.hpp"
#include "softrne/spatial/frame_placement.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {
namespace detail {

/// \brief Inverse of a small symmetric matrix D if it is positive definite (closed form for
/// n = 1, 2; a written-out Cholesky otherwise). Touches only the leading n x n block of Dinv.
/// \return false if D is not positive definite (then Dinv is unspecified).
template <int n, class MatD, class MatDinv>
bool invert_spd_small(const MatD& D, MatDinv& Dinv) {
  using S = typename MatD::Scalar;
  if constexpr (n == 1) {
    if (!(D(0, 0) > S(0))) return false;
    Dinv(0, 0) = S(1) / D(0, 0);
    return true;
  } else if constexpr (n == 2) {
    const S det = D(0, 0) * D(1, 1) - D(0, 1) * D(0, 1);
    if (!(D(0, 0) > S(0)) || !(det > S(0))) return false;
    const S inv_det = S(1) / det;
    Dinv(0, 0) = D(1, 1) * inv_det;
    Dinv(1, 1) = D(0, 0) * inv_det;
    Dinv(0, 1) = -D(0, 1) * inv_det;
    Dinv(1, 0) = Dinv(0, 1);
    return true;
  } else {
    Eigen::Matrix<S, n, n> L = D;
    if (!cholesky_factor_in_place(L)) return false;
    cholesky_inverse_factored(L, Dinv.template topLeftCorner<n, n>());
    return true;
  }
}

/// \brief The two sweeps on the kinematics in data, with data.qddot = tau - b on entry and
/// the accelerations on exit (see the file comment). \return false if some D is not positive
/// definite.
template <class ChainT>
bool articulated_passes(const ChainT& chain, typename ChainT::Data& data) {
  using Scalar = typename ChainT::Scalar;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  // Articulated inertia of everything beyond the current frame, [A B; B^T C] in 3x3 blocks
  // (A, C symmetric), and its force (pf; pn); about the distal origin in distal axes before
  // a segment is visited, about its base origin in base axes after.
  ArticulatedInertia<Scalar> IA;
  Matrix3 &A = IA.A, &B = IA.B, &C = IA.C;
  Vector3 pf = Vector3::Zero(), pn = Vector3::Zero();
  bool ok = true;
  bool beyond = false;  // false while nothing lies beyond the current frame (A = B = C = 0)

  chain.backward(data, [&](const auto& seg, const auto& kin, int i, int offset) {
    using Segment = std::decay_t<decltype(seg)>;
    constexpr int n = Segment::nq;
    constexpr bool shifts = !has_zero_translation<Segment>::value;
    const auto X = placement_of<Segment>(kin);
    const Vector3& r_e = kin.r_base_distal;

    // Into base axes and about the base origin: I -> X^T I X, p -> (R pf; R pn + r_e x R pf).
    if (beyond) {
      X.to_base(IA);
      pf = X.rotate(pf);
      pn = X.shift_torque(X.rotate(pn), pf);
    }

    // The segment's own bodies (own_inertia.hpp), then elimination of its coordinates.
    [[maybe_unused]] OwnBodyInertia<Scalar, n> own;
    if constexpr (Segment::has_body) own_body_inertia(seg, kin, own);
    if constexpr (n > 0) {
      auto& ws = data.articulated[static_cast<std::size_t>(i)];
      const auto Jw = kin.J_distal.template bottomRows<3>();
      // S_e = X^{-1} J: the distal frame's motion per unit qddot, at O.
      Eigen::Matrix<Scalar, 3, n> Sv;
      if constexpr (shifts) {
        Sv = kin.J_distal.template topRows<3>();
        for (int k = 0; k < n; ++k) Sv.col(k) += r_e.cross(Jw.col(k));
      }
      // I^A_O S_e (blocks), then U = coupling + I^A_O S_e and D = joint + S_e^T I^A_O S_e.
      Eigen::Matrix<Scalar, 3, n> ISf = B * Jw, ISn = C * Jw;
      if constexpr (shifts) {
        ISf.noalias() += A * Sv;
        ISn.noalias() += B.transpose() * Sv;
      }
      Eigen::Matrix<Scalar, n, n> D;
      for (int k = 0; k < n; ++k)
        for (int j = 0; j <= k; ++j) {
          Scalar d = Jw.col(j).dot(ISn.col(k));
          if constexpr (shifts) d += Sv.col(j).dot(ISf.col(k));
          if constexpr (Segment::has_body) d += own.joint(j, k);
          D(j, k) = d;
          D(k, j) = d;
        }
      auto U = ws.U.template leftCols<n>();
      U.template topRows<3>() = ISf;
      U.template bottomRows<3>() = ISn;
      if constexpr (Segment::has_body) U += own.coupling;
      auto Dinv = ws.D_inv.template topLeftCorner<n, n>();
      if (!invert_spd_small<n>(D, Dinv)) ok = false;
      // u = tau_i - b_i - S_e^T p^A_O (data.qddot holds tau - b here).
      Eigen::Matrix<Scalar, n, 1> u = data.qddot.template segment<n>(offset);
      u.noalias() -= Jw.transpose() * pn;
      if constexpr (shifts) u.noalias() -= Sv.transpose() * pf;
      ws.u.template head<n>() = u;
      // I^A -= U D^-1 U^T, p^A += U D^-1 u.
      const Eigen::Matrix<Scalar, 6, n> UD = U * Dinv;
      const auto Uf = U.template topRows<3>();
      const auto Un = U.template bottomRows<3>();
      const auto UDf = UD.template topRows<3>();
      const auto UDn = UD.template bottomRows<3>();
      const Matrix3 dA = UDf * Uf.transpose();
      const Matrix3 dC = UDn * Un.transpose();
      for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c) {
          A(r, c) -= dA(r, c);
          C(r, c) -= dC(r, c);
          if (c != r) {
            A(c, r) = A(r, c);
            C(c, r) = C(r, c);
          }
        }
      B.noalias() -= UDf * Un.transpose();
      pf.noalias() += UDf * u;
      pn.noalias() += UDn * u;
    }
    // Plus the own bodies' rigid inertia about O (they move with the base frame's motion).
    if constexpr (Segment::has_body) {
      A.diagonal().array() += own.mass;
      B -= skew(own.first_moment);
      C += own.inertia_origin;
    }
    beyond = true;
  });
  if (!ok) return false;

  // Base to tip: the base is at rest (gravity and velocities are in b).
  Vector3 acc = Vector3::Zero(), alpha = Vector3::Zero();
  chain.forward(data, [&](const auto& seg, const auto& kin, int i, int offset) {
    using Segment = std::decay_t<decltype(seg)>;
    constexpr int n = Segment::nq;
    constexpr bool shifts = !has_zero_translation<Segment>::value;
    const auto X = placement_of<Segment>(kin);
    (void)seg;
    if constexpr (n > 0) {
      const auto& ws = data.articulated[static_cast<std::size_t>(i)];
      const auto U = ws.U.template leftCols<n>();
      Eigen::Matrix<Scalar, n, 1> rhs = ws.u.template head<n>();
      rhs.noalias() -= U.template topRows<3>().transpose() * acc;
      rhs.noalias() -= U.template bottomRows<3>().transpose() * alpha;
      const Eigen::Matrix<Scalar, n, 1> qdd = ws.D_inv.template topLeftCorner<n, n>() * rhs;
      data.qddot.template segment<n>(offset) = qdd;
      // Distal motion a_e = X a_B + J qddot (the shift uses the base's alpha).
      acc = X.point_acceleration(acc, alpha);
      if constexpr (shifts) acc.noalias() += kin.J_distal.template topRows<3>() * qdd;
      alpha.noalias() += kin.J_distal.template bottomRows<3>() * qdd;
    } else {
      acc = X.point_acceleration(acc, alpha);
    }
    acc = X.rotate_back(acc);
    alpha = X.rotate_back(alpha);
  });
  return true;
}

}  // namespace detail

/// \brief Forward dynamics in O(n): \f$\ddot q = M(q)^{-1}(\tau - C(q,\dot q)\dot q - G(q))\f$
/// (eq. 23) by the articulated-body recursion of this file's comment, without forming M.
///
/// Same contract as forward_dynamics(): tau holds every other generalised force (pressures,
/// springs, dampers, effects); C qdot + G is left in data.nonlinear_forces. If a segment's
/// articulated joint inertia D is not positive definite (never, for positive masses), qddot
/// is set to NaN. Allocates nothing (for a built-in scalar type). Unlike forward_dynamics()
/// it leaves no mass matrix or Cholesky factor in data.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace, made by chain.make_data() (data.articulated holds the
///   per-segment articulated inertias).
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \param[in] tau Every generalised force other than inertia and gravity (dim
///   chain.num_coordinates()), as for forward_dynamics().
/// \return The accelerations, stored in data.qddot (NaN if an articulated inertia is not
///   positive definite).
/// \throws std::invalid_argument (DynamicChain only) if q, qdot or tau has another size than
///   the chain or data was made for another chain.
template <class ChainT, class Q, class Qd, class Tau>
const typename ChainT::VectorQ& aba(const ChainT& chain, typename ChainT::Data& data,
                                    const Eigen::MatrixBase<Q>& q,
                                    const Eigen::MatrixBase<Qd>& qdot,
                                    const Eigen::MatrixBase<Tau>& tau) {
  detail::check_argument(chain, "aba", "q", q);
  detail::check_argument(chain, "aba", "qdot", qdot);
  detail::check_argument(chain, "aba", "tau", tau);
  detail::kinematics_and_nonlinear_forces(chain, data, q, qdot);
  data.qddot = tau - data.nonlinear_forces;
  if (!detail::articulated_passes(chain, data))
    data.qddot.setConstant(std::numeric_limits<double>::quiet_NaN());
  return data.qddot;
}

}  // namespace softrne
