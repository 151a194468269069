// Amplitude-dependent damping from the hits' ring-downs: the check that the damping an FRF shows
// is viscous, and the viscous and Coulomb parts when it is not.
//
// Coulomb friction takes a fixed amount of amplitude per cycle: a mode's envelope falls as
// dA/dt = -sigma A - r (sigma = zeta omega, viscous; r, friction), so the apparent damping
// -d ln A / dt / omega = zeta + r / (omega A) grows as the amplitude falls, and an FRF fit gives a
// zeta between the two, with an interval that excludes the viscous truth (the emulator's default
// rig: +15 %). Each used hit's responses after its force window are projected on the modes
// (the identified shapes' pseudo-inverse when the responses are at least as many as the modes,
// else the response the mode moves most), demodulated at the mode's frequency and smoothed twice
// by a boxcar of whole periods (a triangular filter: the other modes fall 26 dB and more below),
// and the envelope A(t) = a exp(-sigma t) - b is fitted (variable projection in sigma) from its
// start down to a tenth of it. Per mode: the apparent damping over the first and the second half
// of the decay (in log amplitude), and over the hits the viscous part zeta_v = sigma / omega and
// the friction rate r = sigma b with their scatter.
//
// The modal friction force follows from r: a mode of unit modal mass whose coordinate q loses
// 2 F_q / k_q per half cycle (k_q = omega^2) decays at dq/dt = -2 F_q / (pi omega), and a friction
// force F_j on each mass j acts on the mode with the first harmonic F_q = sum_j |phi_j| F_j. With
// the same friction on every measured mass, F = F_q / sum_j |phi_j|.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "vibid/ident/impact.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

/// The used hits' responses after their force windows (offsets from the pretrigger taken off),
/// in the units of the recording's sensor.
struct RingDowns {
  double fs_hz = 0.0;
  Quantity sensor = Quantity::kAcceleration;
  std::vector<Eigen::MatrixXd> hits;  ///< Samples x responses, one per used hit.
};

/// The ring-downs of the used hits of an impact estimate made from these signals.
RingDowns RingDownsOf(const ImpactResult& impact, const Eigen::Ref<const Eigen::VectorXd>& force,
                      const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                      Quantity sensor);

struct RingDownOptions {
  /// The envelope is fitted from its start down to this fraction of it, or to 3 times the noise
  /// floor (read in the records' flat tails, its power taken off) where that comes first.
  double end_fraction = 0.02;
  /// Amplitude dependence is reported when the apparent damping of the decay's second half
  /// exceeds that of its first half by this factor (on the hits' means) and the friction rate is
  /// positive beyond its 95 % interval over the hits (so never with one hit).
  double min_late_over_early = 1.15;
  /// Below that rule, friction is suspected (`friction_hint`) where, in ring-downs read through
  /// their decay (two at least), the friction rate lies this many standard errors above 0 and
  /// the bias it puts into an FRF's zeta (2 b / a, as a fraction of zeta) is at least this
  /// fraction of the FRF interval's relative half-width: zeta's interval is then widened down to
  /// the viscous part's. The late/early ratio is no test here: it scatters by 0.06-0.08 over
  /// seeds with and without friction (2-mass rig, 1 mN per mass: 0.89-1.26; none: 0.80-1.09).
  double hint_rate_t = 1.0;
  double hint_bias_over_half_width = 1.0;
  /// A friction term above this (as a fraction of zeta) is no hint: friction of that size is
  /// the amplitude rule's to find, and without it the envelope is misread (the three-mass
  /// chain's records cut 5 s after each hit: mode 1's term tens of percent, no friction).
  double hint_max_bias = 0.1;
  /// Fewer hits than this leave the friction rate's scatter no test (1-2 degrees of freedom): the
  /// beam records' lightly damped modes, without friction, read t 3-3.8 over 2-3 hits.
  std::size_t hint_min_hits = 4;
};

/// The check for every mode of `modes` (shapes mass-normalised, response order of the ring-downs),
/// in the modes' order. A mode whose ring-down cannot be read (no used hit, a smoothing window
/// longer than a third of the records) has `checked` false and a note why.
std::vector<AmplitudeDamping> CheckAmplitudeDependence(const RingDowns& ringdowns,
                                                       const std::vector<ModeEstimate>& modes,
                                                       const RingDownOptions& options = {});

/// The check applied to identified modes: every mode gets its AmplitudeDamping; where the damping
/// depends on amplitude, the FRF's zeta (and its interval, which the ring-downs contradict) gives
/// way to the viscous part with its interval over the hits (withheld, with the reason, with fewer
/// than 2 hits), the mode's `caution` and a warning say so and give the modal friction force.
void ApplyAmplitudeCheck(const RingDowns& ringdowns, ModeIdentification& identification,
                         const RingDownOptions& options = {});

/// "its ring-downs show dry friction (at F Hz ...)" for the first mode of `identification` whose
/// ring-down check found friction (ApplyAmplitudeCheck run first); empty when none did.
std::string FrictionShownBy(const ModeIdentification& identification);

}  // namespace vibid::ident
