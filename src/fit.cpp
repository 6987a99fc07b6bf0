/// \file
/// \brief The one definition of fit/'s heavy entry points (the fitter, the closed loop) for
/// the targets that link softrne::fit_compiled (see SOFTRNE_FIT_INLINE in softrne/config.hpp).
/// The arm layer's come from softrne::sim_compiled (SOFTRNE_USE_COMPILED). The Savitzky-Golay
/// differentiator moved to signals/ but kept fit/'s compiled mode, so it is defined here too.
#define SOFTRNE_COMPILING_FIT
#ifndef SOFTRNE_USE_COMPILED
#define SOFTRNE_USE_COMPILED 1
#endif
#include "softrne/fit/arm_fit.hpp"
#include "softrne/fit/candidates.hpp"
#include "softrne/fit/least_squares.hpp"
#include "softrne/fit/loop.hpp"
#include "softrne/fit/residual_analysis.hpp"
#include "softrne/signals/savitzky_golay.hpp"
