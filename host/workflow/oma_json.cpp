#include "vibid/workflow/oma_json.hpp"

#include <numbers>
#include <vector>

namespace vibid::workflow {
namespace {

std::vector<double> Values(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

}  // namespace

nlohmann::json SsiCovJson(const oma::SsiCovResult& r) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  nlohmann::json modes = nlohmann::json::array();
  for (const oma::OmaMode& m : r.modes) {
    modes.push_back({{"freq_hz", m.omega_rad_s / kTwoPi},
                     {"omega_rad_s", m.omega_rad_s},
                     {"zeta", m.zeta},
                     {"shape", Values(m.shape)},
                     {"mpc", m.mpc},
                     {"order", m.order},
                     {"cluster_size", m.cluster_size},
                     {"found_share", m.found_share},
                     {"ci95",
                      {{"omega_rad_s", m.omega_ci95_rad_s},
                       {"freq_hz", m.omega_ci95_rad_s / kTwoPi},
                       {"zeta", m.zeta_ci95},
                       {"shape", Values(m.shape_ci95)}}}});
  }
  nlohmann::json poles = nlohmann::json::array();
  for (const oma::Pole& p : r.diagram) {
    poles.push_back({{"order", p.order},
                     {"freq_hz", p.omega_rad_s / kTwoPi},
                     {"omega_rad_s", p.omega_rad_s},
                     {"zeta", p.zeta},
                     {"stable", p.stable},
                     {"cluster", p.cluster}});
  }
  return {{"modes", modes},
          {"stabilization", {{"poles", poles}}},
          {"fs_hz", r.fs_hz},
          {"decimation", r.decimation},
          {"block_rows", r.block_rows},
          {"order_max", r.order_max},
          {"channels", r.channels},
          {"samples", r.samples},
          {"singular_values", r.singular_values},
          {"message", r.message}};
}

}  // namespace vibid::workflow
