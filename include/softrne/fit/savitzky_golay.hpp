#pragma once
/// \file
/// \brief Forwards to softrne/signals/savitzky_golay.hpp, where the Savitzky-Golay smoothing
/// differentiator moved (signal processing has its own folder, signals/); kept so that code
/// written against fit/ compiles.
///
/// The old names softrne::fit::SgOptions, savgol_weights and savgol stay available as
/// using-declarations of the softrne::signals ones (the same entities).

#include "softrne/signals/savitzky_golay.hpp"

namespace softrne::fit {
using signals::savgol;
using signals::savgol_weights;
using signals::SgOptions;
}  // namespace softrne::fit
