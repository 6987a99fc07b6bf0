#pragma once
/// \file
/// \brief Fixed-step integrators for controllers and real-time loops: classic
/// Runge-Kutta 4 on a first-order system and semi-implicit (symplectic) Euler
/// on a second-order system. Eigen only; no heap allocation per step.
///
/// Both work with fixed-size vectors (`Eigen::Matrix<double, N, 1>`) and with
/// dynamic ones (`Eigen::VectorXd`); with dynamic vectors the workspace is
/// sized once by its constructor and a step allocates nothing as long as the
/// system's callbacks allocate nothing.

#include <type_traits>
#include <utility>

#include <Eigen/Core>

namespace softrne::sim {

namespace detail {

/// Calls `f(args...)`; returns its bool result, or true when it returns void.
template <class F, class... Args>
bool call_ok(F&& f, Args&&... args) {
  using R = decltype(std::forward<F>(f)(std::forward<Args>(args)...));
  if constexpr (std::is_void_v<R>) {
    std::forward<F>(f)(std::forward<Args>(args)...);
    return true;
  } else {
    static_assert(std::is_convertible_v<R, bool>,
                  "softrne::sim: a system callback must return void or bool");
    return static_cast<bool>(std::forward<F>(f)(std::forward<Args>(args)...));
  }
}

template <class System, class Vector, class = void>
struct has_fixed_step_rhs : std::false_type {};
template <class System, class Vector>
struct has_fixed_step_rhs<System, Vector,
                          std::void_t<decltype(std::declval<System&>().rhs(
                              0.0, std::declval<const Vector&>(), std::declval<Vector&>()))>>
    : std::true_type {};

template <class System, class Vector, class = void>
struct has_acceleration : std::false_type {};
template <class System, class Vector>
struct has_acceleration<System, Vector,
                        std::void_t<decltype(std::declval<System&>().acceleration(
                            0.0, std::declval<const Vector&>(), std::declval<const Vector&>(),
                            std::declval<Vector&>()))>> : std::true_type {};

}  // namespace detail

/// \brief Scratch for rk4_step, built once. `Vector` is a column vector type,
/// fixed-size or dynamic.
template <class Vector = Eigen::VectorXd>
struct Rk4Workspace {
  static_assert(Vector::ColsAtCompileTime == 1,
                "Rk4Workspace: Vector must be a column vector type");
  Vector k1, k2, k3, k4, x_stage;
  /// \var k1
  /// \brief Slope at the step's start.
  /// \var k2
  /// \brief First slope at the midpoint.
  /// \var k3
  /// \brief Second slope at the midpoint.
  /// \var k4
  /// \brief Slope at the step's end.
  /// \var x_stage
  /// \brief The state at which the next slope is evaluated.

  /// \brief Sizes every buffer to n (must equal the fixed size, if any).
  /// \param[in] n The state's size.
  explicit Rk4Workspace(Eigen::Index n = Vector::SizeAtCompileTime > 0 ? Vector::SizeAtCompileTime
                                                                       : 0) {
    resize(n);
  }
  /// \brief Sizes every buffer to n.
  /// \param[in] n The state's size.
  void resize(Eigen::Index n) {
    k1.resize(n);
    k2.resize(n);
    k3.resize(n);
    k4.resize(n);
    x_stage.resize(n);
  }
};

/// \brief One classic Runge-Kutta 4 step of \f$\dot x = f(t, x)\f$ from t to
/// t + dt, in place: on success `x` holds \f$x(t + dt)\f$ (local error
/// \f$O(dt^5)\f$, global \f$O(dt^4)\f$).
///
/// The system provides `rhs(t, x, xdot)` callable with `const Vector&` and
/// `Vector&` (an `Eigen::Ref` or a template parameter works too), returning
/// void or bool. When an evaluation returns false the step stops, `x` is left
/// unchanged and false is returned.
/// \param[in,out] sys The system (its rhs may keep state, e.g. a cursor).
/// \param[in] t The step's start time.
/// \param[in,out] x The state: x(t) on entry, x(t + dt) on success.
/// \param[in] dt The step.
/// \param[in,out] work Scratch of x's size.
/// \return False if an evaluation of rhs returned false.
template <class System, class Vector>
bool rk4_step(System& sys, double t, Vector& x, double dt, Rk4Workspace<Vector>& work) {
  static_assert(detail::has_fixed_step_rhs<System, Vector>::value,
                "rk4_step: System must provide rhs(double t, const Vector& x, Vector& xdot) "
                "(returning void or bool), where Vector is the state vector type");
  eigen_assert(work.k1.size() == x.size() &&
               "rk4_step: workspace size differs from the state size");
  auto f = [&sys](double tt, const Vector& xx, Vector& out) {
    return detail::call_ok([&] { return sys.rhs(tt, xx, out); });
  };
  const double half = 0.5 * dt;
  if (!f(t, x, work.k1)) return false;
  work.x_stage.noalias() = x + half * work.k1;
  if (!f(t + half, work.x_stage, work.k2)) return false;
  work.x_stage.noalias() = x + half * work.k2;
  if (!f(t + half, work.x_stage, work.k3)) return false;
  work.x_stage.noalias() = x + dt * work.k3;
  if (!f(t + dt, work.x_stage, work.k4)) return false;
  x.noalias() += (dt / 6.0) * (work.k1 + 2.0 * work.k2 + 2.0 * work.k3 + work.k4);
  return true;
}

/// \brief Scratch for semi_implicit_euler_step, built once.
template <class Vector = Eigen::VectorXd>
struct SemiImplicitEulerWorkspace {
  static_assert(Vector::ColsAtCompileTime == 1,
                "SemiImplicitEulerWorkspace: Vector must be a column vector type");
  Vector qdd;  ///< the acceleration at the step's start

  /// \brief Sizes the buffer to n (must equal the fixed size, if any).
  /// \param[in] n The number of coordinates.
  explicit SemiImplicitEulerWorkspace(Eigen::Index n = Vector::SizeAtCompileTime > 0
                                                           ? Vector::SizeAtCompileTime
                                                           : 0) {
    resize(n);
  }
  /// \brief Sizes the buffer to n.
  /// \param[in] n The number of coordinates.
  void resize(Eigen::Index n) { qdd.resize(n); }
};

/// \brief One semi-implicit (symplectic) Euler step of \f$\ddot q = a(t, q, \dot q)\f$,
/// in place:
/// \f$\dot q_{k+1} = \dot q_k + dt\, a(t_k, q_k, \dot q_k)\f$,
/// \f$q_{k+1} = q_k + dt\, \dot q_{k+1}\f$.
///
/// First order, but for conservative systems the energy error stays bounded
/// (no drift), which is why it suits long controller loops. The system
/// provides `acceleration(t, q, qd, qdd)` callable with `const Vector&`,
/// `const Vector&`, `Vector&`, returning void or bool; on false, `q` and `qd`
/// are left unchanged and false is returned.
/// \param[in,out] sys The system.
/// \param[in] t The step's start time.
/// \param[in,out] q The coordinates, advanced on success.
/// \param[in,out] qd Their rates, advanced on success.
/// \param[in] dt The step.
/// \param[in,out] work Scratch of q's size.
/// \return False if the acceleration returned false.
template <class System, class Vector>
bool semi_implicit_euler_step(System& sys, double t, Vector& q, Vector& qd, double dt,
                              SemiImplicitEulerWorkspace<Vector>& work) {
  static_assert(
      detail::has_acceleration<System, Vector>::value,
      "semi_implicit_euler_step: System must provide acceleration(double t, const Vector& q, "
      "const Vector& qd, Vector& qdd) (returning void or bool)");
  eigen_assert(work.qdd.size() == q.size() && qd.size() == q.size() &&
               "semi_implicit_euler_step: workspace, q and qd sizes differ");
  if (!detail::call_ok(
          [&] { return sys.acceleration(t, std::as_const(q), std::as_const(qd), work.qdd); }))
    return false;
  qd.noalias() += dt * work.qdd;
  q.noalias() += dt * qd;
  return true;
}

}  // namespace softrne::sim
