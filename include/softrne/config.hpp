#pragma once
/// \file
/// \brief Version and assertion macros shared by every softrne header.

#include <cstdio>
#include <cstdlib>

#define SOFTRNE_VERSION_MAJOR 0  ///< Major version (the CMake project's VERSION).
#define SOFTRNE_VERSION_MINOR 1  ///< Minor version.
#define SOFTRNE_VERSION_PATCH 0  ///< Patch version.

/// \brief Debug-build check of API preconditions (sizes, a Data made for another chain).
/// Prints file:line and the message, then aborts; compiled out with NDEBUG.
#ifndef NDEBUG
#define SOFTRNE_ASSERT(cond, msg)                                                       \
  do {                                                                                  \
    if (!(cond)) {                                                                      \
      std::fprintf(stderr, "%s:%d: softrne assertion failed: %s\n", __FILE__, __LINE__, \
                   msg);                                                                \
      std::abort();                                                                     \
    }                                                                                   \
  } while (false)
#else
#define SOFTRNE_ASSERT(cond, msg) \
  do {                            \
  } while (false)
#endif

/// \brief Forces a lambda inline (`[&](auto k) SOFTRNE_LAMBDA_INLINE { ... }`), as
/// EIGEN_ALWAYS_INLINE does a function: GCC otherwise leaves small generic lambdas out of line
/// in the larger translation units (measured in mass_matrix, docs/performance.md).
#if defined(__GNUC__)
#define SOFTRNE_LAMBDA_INLINE __attribute__((always_inline))
#else
#define SOFTRNE_LAMBDA_INLINE
#endif

/// \brief Header-only or compiled: the heavy entry points of the arm layer (arm/, sim/:
/// SOFTRNE_SIM_*) and of fit/ (SOFTRNE_FIT_*).
///
/// softrne is header-only: by default these functions are `inline` and compiled in every
/// translation unit that calls them. Each such unit then instantiates the simulator, the
/// AutoDiff Jacobian, the fitter and the loop anew (one to three minutes of compiler time
/// per unit at -O3), which is what a project with many of them pays for (ours: the tests and
/// tools). A target that links softrne's compiled libraries (CMake `softrne::sim_compiled`,
/// `softrne::fit_compiled`, which define SOFTRNE_USE_COMPILED for it) sees declarations
/// only, and src/sim.cpp and src/fit.cpp (which define SOFTRNE_COMPILING_SIM /
/// SOFTRNE_COMPILING_FIT) hold the one definition. The same idea as Pinocchio's explicit
/// template instantiation library; the code is the same text in both modes.
///
/// Not only entry points: any plain `inline` function whose body uses the dynamics, a runtime
/// chain or a dynamic-size decomposition costs every unit that includes its header, called or
/// not, since GCC instantiates the templates an inline body uses. Such helpers take this form
/// too (static_equilibrium: 9 s of g++ front end per unit; fit/arm_fit.hpp's marker helpers
/// about 15 s).
///
/// Usage at a definition:
///
///     SOFTRNE_FIT_INLINE FitResult fit_arm(...)
///     #if SOFTRNE_FIT_BODIES
///     { ...body... }
///     #else
///     ;
///     #endif
#if defined(SOFTRNE_COMPILING_SIM)
#define SOFTRNE_SIM_INLINE
#define SOFTRNE_SIM_BODIES 1
#elif defined(SOFTRNE_USE_COMPILED)
#define SOFTRNE_SIM_INLINE
#define SOFTRNE_SIM_BODIES 0
#else
#define SOFTRNE_SIM_INLINE inline
/// \brief 1 where the sim/ entry points' bodies are compiled (header-only mode, or
/// src/sim.cpp), 0 where only their declarations are seen (SOFTRNE_USE_COMPILED).
#define SOFTRNE_SIM_BODIES 1
#endif

#if defined(SOFTRNE_COMPILING_FIT)
#define SOFTRNE_FIT_INLINE
#define SOFTRNE_FIT_BODIES 1
#elif defined(SOFTRNE_USE_COMPILED)
#define SOFTRNE_FIT_INLINE
#define SOFTRNE_FIT_BODIES 0
#else
/// \brief `inline` in header-only mode, nothing where fit/'s entry points are compiled once
/// (see SOFTRNE_SIM_INLINE).
#define SOFTRNE_FIT_INLINE inline
/// \brief 1 where fit/'s entry points' bodies are compiled, 0 where only their declarations
/// are seen (see SOFTRNE_SIM_BODIES).
#define SOFTRNE_FIT_BODIES 1
#endif
