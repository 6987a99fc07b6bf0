#pragma once
/// \file
/// \brief Joint-space inertia matrix M(q).

#include <type_traits>

#include <Eigen/Core>

#include "softrne/algorithms/bias.hpp"
#include "softrne/algorithms/kinematics.hpp"
#include "softrne/algorithms/own_inertia.hpp"
#include "softrne/algorithms/rnea.hpp"
#include "softrne/spatial/frame_placement.hpp"
#include "softrne/spatial/inertia_transforms.hpp"
#include "softrne/spatial/skew.hpp"

namespace softrne {
namespace detail {

/// Stands in for OwnBodyInertia where mass_matrix_passes folds the own body in itself.
struct NoOwnBlocks {};

/// \brief M on the kinematics already in data (any qdot; only q matters).
///
/// \f$M = \sum_b J_b^T \mathcal I_b J_b\f$ over the bodies, evaluated as the composite-body
/// form of the RNE with qddot = e_k and no gravity or velocity terms (section III-D): one
/// backward sweep, tip to base, carrying
/// - the composite of every body beyond the current frame (mass, first moment, inertia about
///   the frame origin): it is rigidly attached to the segment's distal frame, so a unit
///   \f$\ddot q_k\f$ of the segment's own coordinate k makes it push back with the wrench
///   \f$(m a + \alpha\times h,\; h\times a + I_O\alpha)\f$, (a, alpha) = column k of J_distal;
///   the segment's own body adds \f$m J_{com,k}\f$ and \f$I\alpha\f$ (it does not move rigidly:
///   its centre of mass follows \f$\partial r_c/\partial q\f$, as in the RNE's forward step);
/// - for every coordinate k already passed, that wrench (column k of 6 x nq "pending"
///   wrenches), carried to each upstream segment like the RNE's backward step carries the
///   distal wrench, where \f$M_{jk} = J_{distal,j}^T w_k\f$ for its coordinates j.
/// The segment kinematics (trigonometry, Jacobians, inertia) are computed once and shared by
/// all columns. Cost O(n nq) like nq RNE passes (what this replaced), with a much smaller
/// constant: per segment and pending column one cross product (segments that translate) or
/// the projection (segments with coordinates); beyond a few pending wrenches they are no
/// longer rotated (see "lazy" below). Each entry is computed once and written to both
/// triangles, so M is exactly symmetric.
///
/// Workspace: the pending wrenches live in data.mass_factor (nq >= 6; a small local buffer
/// otherwise), so mass_matrix() overwrites the Cholesky factor a previous forward_dynamics()
/// left there (forward_dynamics() itself refactorises after).
template <class ChainT>
void mass_matrix_passes(const ChainT& chain, typename ChainT::Data& data) {
  using Scalar = typename ChainT::Scalar;
  using Vector3 = Eigen::Matrix<Scalar, 3, 1>;
  using Matrix3 = Eigen::Matrix<Scalar, 3, 3>;
  const int nq = chain.num_coordinates();
  auto& M = data.mass_matrix;
  Eigen::Matrix<Scalar, 6, 6> small_buffer;
  Scalar* buffer = nq >= 6 ? data.mass_factor.data() : small_buffer.data();
  Eigen::Map<Eigen::Matrix<Scalar, 6, Eigen::Dynamic>> P(buffer, 6, nq);  // pending wrenches
  int first_pending = nq;  // pending columns: [first_pending, nq)
  // While few wrenches are pending, a turning segment rotates each into its base orientation.
  // Beyond that they keep one orientation ("lazy"): G maps it to the current frame's
  // (v_cur = G v_pending) and each segment brings its Jacobian, offset and new wrenches into
  // it instead: O(1) per segment rather than two 3x3 rotations per segment and pending column.
  constexpr int kRotateDirectly = 4;  // pending wrenches rotated one by one, at most
  Matrix3 G = Matrix3::Identity();
  bool lazy = false;

  // Composite beyond the current frame: mass, first moment, inertia about the frame origin,
  // in the distal frame of the segment being visited (after it: in its base frame).
  RigidInertia<Scalar> composite;

  chain.backward(data, [&](const auto& seg, const auto& kin, int, int offset) {
    using Segment = std::decay_t<decltype(seg)>;
    constexpr int n = Segment::nq;
    const Vector3& r_e = kin.r_base_distal;

    constexpr bool turns = !has_identity_rotation<Segment>::value;
    constexpr bool shifts = !has_zero_translation<Segment>::value;
    // Own mass as one lumped body, or as rigid sub-bodies (distributed CC joint: their
    // composite, wrenches for qddot = e_k and joint-space inertia from own_body_inertia). The
    // lumped body's blocks are the same (own_inertia.hpp's add_body), folded into the sweep
    // instead: its I_c joins the composite before the one rotation by R, its force m J_com
    // and its share m J_com^T J_com are formed per column below. Taking them from
    // own_body_inertia was measured 3-14 % slower on the lumped chains (an extra rotation
    // and the 6 x n coupling per segment; rev6 1.12-1.14x, the paper's arm 1.08x);
    // tests/core/test_articulated_body.cpp (OwnBodyInertia.*) checks the two against each other.
    constexpr bool lumped = Segment::has_body && num_sub_bodies<Segment> == 0;
    constexpr bool sub_bodies = num_sub_bodies<Segment> > 0;
    std::conditional_t<sub_bodies, OwnBodyInertia<Scalar, n>, NoOwnBlocks> own;
    if constexpr (sub_bodies) own_body_inertia(seg, kin, own);
    // Pending wrenches (about the distal origin): their orientation into the base frame's
    // (X.rotate: R's product, or its fast path about a coordinate axis).
    const auto X = placement_of<Segment>(kin);
    if constexpr (turns) {
      if (lazy) {
        for (int c = 0; c < 3; ++c) G.col(c) = X.rotate(G.col(c));
      } else if (nq - first_pending > kRotateDirectly) {
        G = kin.R_base_distal;
        lazy = true;
      } else {
        for (int c = first_pending; c < nq; ++c) {
          const Vector3 f = P.col(c).template head<3>(), t = P.col(c).template tail<3>();
          P.col(c).template head<3>() = X.rotate(f);
          P.col(c).template tail<3>() = X.rotate(t);
        }
      }
    }
    // The composite in the base orientation (about the distal origin), plus the own body's
    // inertia about its centre of mass: both turn with alpha alike.
    if constexpr (lumped) composite.inertia += kin.inertia_com;
    X.rotate(composite);
    const Scalar& c_mass = composite.mass;
    const Vector3& h = composite.first_moment;
    const Matrix3& I_rot = composite.inertia;

    if constexpr (n > 0) {
      const auto Jv = kin.J_distal.template topRows<3>();
      const auto Jw = kin.J_distal.template bottomRows<3>();
      // Rows of this segment against the coordinates beyond it, with its Jacobian in the
      // pending wrenches' orientation. (A segment whose distal origin never moves, shifts ==
      // false, has J_v = 0.)
      auto project = [&](const auto& Jw_p, const auto& Jv_p) {
        for (int c = first_pending; c < nq; ++c) {
          Eigen::Matrix<Scalar, n, 1> m = Jw_p.transpose() * P.col(c).template tail<3>();
          if constexpr (shifts) m.noalias() += Jv_p.transpose() * P.col(c).template head<3>();
          M.template block<n, 1>(offset, c) = m;
          M.template block<1, n>(c, offset) = m.transpose();
        }
      };
      if (lazy) {
        using Matrix3n = Eigen::Matrix<Scalar, 3, n>;
        const Matrix3n Jw_p = G.transpose() * Jw;
        Matrix3n Jv_p;
        if constexpr (shifts) Jv_p.noalias() = G.transpose() * Jv;
        project(Jw_p, Jv_p);
      } else {
        project(Jw, Jv);
      }
      // Its own columns: the reaction of the composite (rigid with the distal frame) and of
      // the own body (centre of mass along J_com) to qddot = e_k.
      for (int k = 0; k < n; ++k) {
        const Vector3 alpha = Jw.col(k);
        // Composite about the distal origin, own body about its centre of mass.
        Vector3 f_s = cross3(alpha, h);
        Vector3 t = times(I_rot, alpha);
        if constexpr (shifts) {
          const Vector3 a = Jv.col(k);
          f_s += c_mass * a;
          t += cross3(h, a);
        }
        Vector3 f_b = Vector3::Zero();
        if constexpr (lumped) f_b = seg.mass * kin.J_com.col(k);
        for (int j = 0; j <= k; ++j) {
          Scalar m_jk = Jw.col(j).dot(t);
          if constexpr (shifts) m_jk += Jv.col(j).dot(f_s);
          if constexpr (lumped) m_jk += kin.J_com.col(j).dot(f_b);
          if constexpr (sub_bodies) m_jk += own.joint(j, k);
          M(offset + j, offset + k) = m_jk;
          M(offset + k, offset + j) = m_jk;
        }
        // Its wrench about the distal origin, base orientation (the own body's force acts at
        // its centre of mass).
        P.col(offset + k).template head<3>() = f_s + f_b;
        if constexpr (lumped)
          P.col(offset + k).template tail<3>() = t + cross3(kin.r_base_com - r_e, f_b);
        else
          P.col(offset + k).template tail<3>() = t;
        if constexpr (sub_bodies) {  // own wrench about the base origin -> distal origin
          const Vector3 f_own = own.coupling.col(k).template head<3>();
          P.col(offset + k).template head<3>() += f_own;
          P.col(offset + k).template tail<3>() +=
              own.coupling.col(k).template tail<3>() - cross3(r_e, f_own);
        }
      }
      // The new wrenches (base orientation) into the pending ones' orientation.
      if (lazy) {
        for (int k = 0; k < n; ++k) {
          const Vector3 f = P.col(offset + k).template head<3>();
          const Vector3 t = P.col(offset + k).template tail<3>();
          P.col(offset + k).template head<3>() = transpose_times(G, f);
          P.col(offset + k).template tail<3>() = transpose_times(G, t);
        }
      }
      first_pending = offset;
    }
    // Every pending wrench about the base origin; the composite likewise (shift by r_e),
    // plus the own body (at r_c).
    if constexpr (shifts) {
      if (first_pending < nq) {
        // r_e in the pending wrenches' orientation
        const Vector3 r_p = lazy ? transpose_times(G, r_e) : r_e;
        for (int c = first_pending; c < nq; ++c) {
          const Vector3 f = P.col(c).template head<3>();
          P.col(c).template tail<3>() += cross3(r_p, f);
        }
      }
    }
    X.shift_to_base(composite);
    if constexpr (lumped) {  // its inertia about its centre of mass is in already
      const Vector3& r_c = kin.r_base_com;
      add_shift(composite.inertia, r_c, Vector3(Scalar(0.5) * seg.mass * r_c));
      composite.first_moment += seg.mass * r_c;
      composite.mass += seg.mass;
    } else if constexpr (sub_bodies) {
      composite.inertia += own.inertia_origin;
      composite.first_moment += own.first_moment;
      composite.mass += own.mass;
    }
  });
}

}  // namespace detail

/// \brief The joint-space inertia matrix M(q) of eq. 23, symmetric positive definite (exactly
/// symmetric). Column k is what the paper's section III-D obtains from the RNE with
/// qddot = e_k and qdot = g = 0, here in one composite-body sweep (see mass_matrix_passes).
/// Uses data.mass_factor as workspace.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace, made by chain.make_data().
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \return M(q), stored in data.mass_matrix.
/// \throws std::invalid_argument (DynamicChain only) if q has another size than the chain or
///   data was made for another chain.
template <class ChainT, class Q>
const typename ChainT::MatrixQ& mass_matrix(const ChainT& chain, typename ChainT::Data& data,
                                            const Eigen::MatrixBase<Q>& q) {
  detail::check_argument(chain, "mass_matrix", "q", q);
  data.qdot_zero.setZero();
  compute_kinematics(chain, data, q, data.qdot_zero);
  detail::mass_matrix_passes(chain, data);
  return data.mass_matrix;
}

/// \brief M(q) and C(q,qdot) qdot + G(q) from one kinematics evaluation: what forward dynamics
/// (eq. 23) needs. Results in data.mass_matrix and data.nonlinear_forces.
///
/// \tparam ChainT A Chain<...> or a DynamicChain<Scalar>.
/// \param[in] chain The model.
/// \param[in,out] data Its workspace, made by chain.make_data(); receives both results.
/// \param[in] q The coordinates (dim chain.num_coordinates()).
/// \param[in] qdot Their rates (dim chain.num_coordinates()).
/// \throws std::invalid_argument (DynamicChain only) if q or qdot has another size than the
///   chain or data was made for another chain.
template <class ChainT, class Q, class Qd>
void mass_matrix_and_bias(const ChainT& chain, typename ChainT::Data& data,
                          const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<Qd>& qdot) {
  detail::check_argument(chain, "mass_matrix_and_bias", "q", q);
  detail::check_argument(chain, "mass_matrix_and_bias", "qdot", qdot);
  detail::kinematics_and_nonlinear_forces(chain, data, q, qdot);
  detail::mass_matrix_passes(chain, data);
}

}  // namespace softrne
