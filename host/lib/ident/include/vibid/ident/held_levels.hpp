// A force channel that holds levels and jumps between them: a step, a controller's pulse, a square
// wave or a held random command (a motor's voltage). No hammer test: its spectrum has no energy
// between a step's lines, where an FRF is noise and modes show up by the dozen, its level changes
// read as hits, and it is seldom a force at all.
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Core>

namespace vibid::ident {

struct HeldLevels {
  /// At least kHeldFraction of the samples repeat the previous one (within 1e-3 of the range),
  /// the channel jumps (by more than a tenth of its range) at least once and on at most a tenth
  /// of its samples, and it is away from its median (by more than a tenth of its largest
  /// excursion) on more than kHeldMinAway of its samples: a hammer record on a converter repeats
  /// its resting code as often, but leaves it for a few milliseconds per hit only.
  bool held = false;
  double held_fraction = 0.0;  ///< Samples that repeat the previous one.
  std::size_t jumps = 0;       ///< Changes by more than a tenth of the range.
  double away_fraction = 0.0;  ///< Samples away from the median.
  std::string description;     ///< What was found, one clause.
};

inline constexpr double kHeldFraction = 0.9;
inline constexpr double kHeldMinAway = 0.02;

HeldLevels CheckHeldLevels(const Eigen::Ref<const Eigen::VectorXd>& force);

}  // namespace vibid::ident
