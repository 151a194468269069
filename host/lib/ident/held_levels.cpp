#include "vibid/ident/held_levels.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace vibid::ident {

HeldLevels CheckHeldLevels(const Eigen::Ref<const Eigen::VectorXd>& force) {
  HeldLevels out;
  const Eigen::Index n = force.size();
  if (n < 16 || !force.allFinite()) return out;
  const double range = force.maxCoeff() - force.minCoeff();
  if (!(range > 0.0)) return out;
  std::size_t held = 0;
  for (Eigen::Index i = 1; i < n; ++i) {
    const double step = std::abs(force[i] - force[i - 1]);
    if (step <= 1e-3 * range) ++held;
    if (step > 0.1 * range) ++out.jumps;
  }
  std::vector<double> sorted(force.data(), force.data() + n);
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median = sorted[static_cast<std::size_t>(n / 2)];
  const double excursion = (force.array() - median).abs().maxCoeff();
  const auto away = static_cast<double>(((force.array() - median).abs() > 0.1 * excursion).count());
  const auto steps = static_cast<double>(n - 1);
  out.held_fraction = static_cast<double>(held) / steps;
  out.away_fraction = away / static_cast<double>(n);
  out.held = out.held_fraction >= kHeldFraction && out.jumps >= 1 &&
             static_cast<double>(out.jumps) <= 0.1 * steps && out.away_fraction > kHeldMinAway;
  std::ostringstream d;
  d.precision(3);
  d << (out.held ? "it holds levels (" : "it does not hold levels (") << 100.0 * out.held_fraction
    << " % of its samples repeat the previous one, " << out.jumps << " jump(s), "
    << 100.0 * out.away_fraction << " % of the record away from its median)";
  out.description = d.str();
  return out;
}

}  // namespace vibid::ident
