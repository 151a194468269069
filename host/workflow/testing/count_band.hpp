// Test support: the band a count of false alarms must fall in when each reference states its own
// rate (WatchReference's mean and 95 % band).
#pragma once

#include <cmath>

#include "vibid/workflow/watch_session.hpp"

namespace vibid::workflow::testing {

// The count's band over references watched `hours` each: the sum of the references' mean rates,
// its variance Poisson's plus the references' own spread (their 95 % band as ± 2 standard
// deviations); 3.3 standard deviations each side (99.9 %).
struct CountBand {
  double expected = 0.0;
  double variance = 0.0;
  void Add(const WatchReference& r, double hours) {
    expected += r.false_alarms_per_hour_mean * hours;
    const double sd = (r.false_alarms_per_hour_high - r.false_alarms_per_hour_low) / 4.0 * hours;
    variance += r.false_alarms_per_hour_mean * hours + sd * sd;
  }
  /// The sequential test's rates instead of the window's.
  void AddSequential(const WatchReference& r, double hours) {
    expected += r.sequential_false_alarms_per_hour_mean * hours;
    const double sd =
        (r.sequential_false_alarms_per_hour_high - r.sequential_false_alarms_per_hour_low) / 4.0 *
        hours;
    variance += r.sequential_false_alarms_per_hour_mean * hours + sd * sd;
  }
  double Low() const { return expected - 3.3 * std::sqrt(variance); }
  double High() const { return expected + 3.3 * std::sqrt(variance); }
};

}  // namespace vibid::workflow::testing
