#pragma once
/// \file
/// \brief Forwards to softrne/signals/pchip.hpp, where PchipSignal moved (signal processing
/// has its own folder, signals/); kept so that code written against sim/ compiles.
///
/// The old name softrne::sim::PchipSignal stays available as a using-declaration of
/// softrne::signals::PchipSignal (the same type).

#include "softrne/signals/pchip.hpp"

namespace softrne::sim {
using signals::PchipSignal;
}  // namespace softrne::sim
