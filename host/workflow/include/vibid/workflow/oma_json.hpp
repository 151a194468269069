// Output-only modes (SSI-cov) as JSON, for the front ends that show them (Python's
// vibid.ssi_cov): the modes with their 95 % half-widths and the stabilization diagram.
#pragma once

#include <nlohmann/json.hpp>

#include "vibid/oma/ssi_cov.hpp"

namespace vibid::workflow {

/// {"modes": [{freq_hz, omega_rad_s, zeta, shape, mpc, order, cluster_size, found_share,
/// ci95: {omega_rad_s, freq_hz, zeta, shape}}], "stabilization": {"poles": [{order, freq_hz,
/// omega_rad_s, zeta, stable, cluster}]}, fs_hz (analysed, after decimation), decimation,
/// block_rows, order_max, channels, samples, singular_values, message}.
nlohmann::json SsiCovJson(const oma::SsiCovResult& r);

}  // namespace vibid::workflow
