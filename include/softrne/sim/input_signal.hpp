#pragma once
/// \file
/// \brief Forwards to softrne/signals/input_signal.hpp, where InputSignal moved (signal
/// processing has its own folder, signals/); kept so that code written against sim/ compiles.
///
/// The old names softrne::sim::InputSignal, Interpolation, Side and SignalCursor stay
/// available as using-declarations of the softrne::signals ones (the same types).

#include "softrne/signals/input_signal.hpp"

namespace softrne::sim {
using signals::InputSignal;
using signals::Interpolation;
using signals::Side;
using signals::SignalCursor;
}  // namespace softrne::sim
