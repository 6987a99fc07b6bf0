#pragma once
/// \file
/// \brief Linearisation of an arm's state equation for control: the continuous pair
/// A = df/dx, B = df/dp at a state and pressure (exact, ArmJacobian's AutoDiff through eq. 23
/// with the pressure maps, the effects and their states), and its zero-order-hold
/// discretisation for a sample time h by the matrix exponential of the augmented matrix.
///
/// Around (x*, p*) with f* = f(x*, p*):
/// \f$\dot{\delta x} = f^* + A\,\delta x + B\,\delta p\f$. With \f$\delta p\f$ held over a
/// sample, \f$\delta x_{k+1} = A_d\,\delta x_k + B_d\,\delta p_k + c_d\f$, where
/// \f$\exp\!\left(\begin{bmatrix}A & B & f^*\\ 0 & 0 & 0\end{bmatrix} h\right) =
/// \begin{bmatrix}A_d & B_d & c_d\\ 0 & I & 0\\ 0 & 0 & 1\end{bmatrix}\f$ (Van Loan); c_d = 0
/// at an equilibrium (f* = 0).
///
/// A transport delay of the pressures (the input_delay effect) is not part of f and so not of
/// A, B: a discrete model of a delayed arm needs extra states for the delayed inputs.

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <unsupported/Eigen/MatrixFunctions>

#include "softrne/config.hpp"
#include "softrne/arm/arm_description.hpp"
#include "softrne/sim/arm_jacobian.hpp"

namespace softrne::sim {

/// \brief The continuous linearisation of x' = f(x, p) at (x, p).
struct Linearisation {
  Eigen::VectorXd x;  ///< the state it was taken at, [q, qdot, effect states]
  Eigen::VectorXd p;  ///< the pressures it was taken at, Pa
  Eigen::VectorXd f;  ///< f(x, p): zero at an equilibrium
  Eigen::MatrixXd A;  ///< df/dx, n x n
  Eigen::MatrixXd B;  ///< df/dp, n x num_inputs
};

/// \brief The zero-order-hold discretisation of a Linearisation for sample time h.
struct DiscreteLinearisation {
  double h = 0;        ///< sample time, s
  Eigen::MatrixXd Ad;  ///< exp(A h)
  Eigen::MatrixXd Bd;  ///< \f$\int_0^h e^{As}ds\,B\f$
  Eigen::VectorXd cd;  ///< \f$\int_0^h e^{As}ds\,f^*\f$: the drift off an equilibrium
};

/// \brief A and B of the arm at (x, p), exact (forward-mode AutoDiff through ArmDynamics).
/// \param[in,out] f The arm's state equation and its Jacobians (reused along a trajectory).
/// \param[in] x The state, size f.num_states().
/// \param[in] p The pressures, Pa, size f.num_inputs().
/// \return The linearisation.
/// \throws std::invalid_argument on wrong sizes, or if f or its derivatives are not finite at
///   (x, p).
SOFTRNE_SIM_INLINE Linearisation linearise(ArmJacobian& f, const Eigen::VectorXd& x,
                                           const Eigen::VectorXd& p)
#if SOFTRNE_SIM_BODIES
{
  const int n = f.num_states(), m = f.num_inputs();
  if (x.size() != n || p.size() != m)
    throw std::invalid_argument("linearise: the state has size " + std::to_string(x.size()) +
                                " and the pressures " + std::to_string(p.size()) +
                                "; the arm has " + std::to_string(n) + " states and " +
                                std::to_string(m) + " inputs");
  Linearisation lin;
  lin.x = x;
  lin.p = p;
  lin.f.resize(n);
  lin.A.resize(n, n);
  lin.B.resize(n, m);
  if (!f.rhs(x, p, lin.f) || !f.jacobians(x, p, lin.A, lin.B))
    throw std::invalid_argument("linearise: f(x, p) or its derivatives are not finite there");
  return lin;
}
#else
;
#endif

/// \brief A and B of the arm `desc` at (x, p) (builds an ArmJacobian once; to linearise along
/// a trajectory, hold one and call linearise(ArmJacobian&, ...)).
/// \param[in] desc The arm.
/// \param[in] x The state, size desc.num_states().
/// \param[in] p The pressures, Pa, size desc.num_inputs.
/// \return The linearisation.
/// \throws std::invalid_argument as linearise(ArmJacobian&, ...).
SOFTRNE_SIM_INLINE Linearisation linearise(const ArmDescription& desc, const Eigen::VectorXd& x,
                                           const Eigen::VectorXd& p)
#if SOFTRNE_SIM_BODIES
{
  ArmJacobian f(desc);
  return linearise(f, x, p);
}
#else
;
#endif

/// \brief The zero-order-hold discretisation for sample time h: the exponential of the
/// augmented matrix [[A, B, f],[0, 0, 0]] h (see the file comment).
/// \param[in] lin A continuous linearisation.
/// \param[in] h The sample time, s (> 0, finite).
/// \return Ad, Bd and cd.
/// \throws std::invalid_argument if h is not positive and finite.
SOFTRNE_SIM_INLINE DiscreteLinearisation discretise_zoh(const Linearisation& lin, double h)
#if SOFTRNE_SIM_BODIES
{
  if (!(h > 0) || !std::isfinite(h))
    throw std::invalid_argument("discretise_zoh: the sample time must be positive and finite");
  const Eigen::Index n = lin.A.rows(), m = lin.B.cols();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + m + 1, n + m + 1);
  M.topLeftCorner(n, n) = lin.A * h;
  M.block(0, n, n, m) = lin.B * h;
  M.block(0, n + m, n, 1) = lin.f * h;
  const Eigen::MatrixXd E = M.exp();
  DiscreteLinearisation d;
  d.h = h;
  d.Ad = E.topLeftCorner(n, n);
  d.Bd = E.block(0, n, n, m);
  d.cd = E.block(0, n + m, n, 1);
  return d;
}
#else
;
#endif

}  // namespace softrne::sim
