#pragma once
/// \file
/// \brief The sensor noise of measured angles, estimated from the data alone, and the error a
/// perfect model would still show (the noise floor of the closed loop).
///
/// The estimate itself is generic signal processing and lives in signals/noise_sigma.hpp;
/// softrne::fit::estimate_noise_sigma stays available as a using-declaration.

#include "softrne/signals/noise_sigma.hpp"

namespace softrne::fit {

using signals::estimate_noise_sigma;

/// \brief Median absolute error that pure N(0, sigma^2) noise gives: 0.6745 sigma. A
/// simulation whose median error reaches it has nothing systematic left to explain.
/// \param[in] sigma The noise's standard deviation.
/// \return 0.6745 sigma.
inline double noise_floor_median(double sigma) { return 0.6744897501960817 * sigma; }

}  // namespace softrne::fit
