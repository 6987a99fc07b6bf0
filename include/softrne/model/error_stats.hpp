#pragma once
/// \file
/// \brief Forwards to softrne/signals/error_stats.hpp, where the error statistics moved (they
/// compare two sampled signals and need no model); kept so that code including it compiles.
///
/// The old names softrne::ErrorSummary, ErrorStats, error_stats and format_error_table stay
/// available as using-declarations of the softrne::signals ones (the same entities).

#include "softrne/signals/error_stats.hpp"

namespace softrne {
using signals::error_stats;
using signals::ErrorStats;
using signals::ErrorSummary;
using signals::format_error_table;
}  // namespace softrne
