// A rig that changes while it runs: the rig file's "changes", steps and slow drifts of a mass, a
// spring or a damper, timed from each acquisition's start (the watch features' test bench:
// docs/watch.md). This file reads and writes them, checks what they do to the rig, gives the
// parameters in force at any time, and says when the simulator must rebuild its discrete system.
//
// A change's target is a chain parameter as the dynamics use it: a mass change adds to the
// effective mass (masses_kg · (1 − effective_mass_loss)), a weight bolted to the plate moving
// with it whole; springs and dampers are the chain's, so a mass tested alone on its own spring
// sees the same changes as the chain.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vibid::emu {

struct RigSpec;

enum class ChangeTarget : std::uint8_t { kMass, kSpring, kDamper };

/// One entry of "changes": {"at_s": 600, "mass": 2, "add_kg": 0.08} (a step), or with
/// "over_s": 300 a drift that ramps linearly from at_s to at_s + over_s. Springs take
/// "add_n_per_m", dampers "add_ns_per_m"; targets count from 1 in the file.
struct RigChange {
  double at_s = 0.0;  ///< time from the acquisition's start, s (>= 0)
  ChangeTarget target = ChangeTarget::kMass;
  int index = 0;        ///< 0-based mass, spring or damper
  double add = 0.0;     ///< kg, N/m or N s/m, the target's unit
  double over_s = 0.0;  ///< 0: a step at at_s; > 0: a drift's duration, s

  /// The part of `add` in force at t_s: 0 before at_s, 1 from at_s on for a step, the linear
  /// ramp (t_s − at_s) / over_s clipped to [0, 1] for a drift.
  double FractionAt(double t_s) const;
  bool operator==(const RigChange&) const = default;
};

/// The chain's parameters as the dynamics use them: effective masses (kg), springs (N/m),
/// dampers (N s/m), one each per mass.
struct ChainParameters {
  std::vector<double> masses_kg, springs_n_per_m, dampers_ns_per_m;
};

/// The rig's parameters with the changes in force at t_s (the exact ramps).
ChainParameters ParametersAt(const RigSpec& rig, double t_s);

/// Reads "changes" of a rig of `masses` masses. @throws InputError naming `source`, the entry
/// ("changes"[i]) and the field.
std::vector<RigChange> ChangesFromJson(const nlohmann::json& list, std::size_t masses,
                                       const std::string& source);
nlohmann::json ChangesToJson(const std::vector<RigChange>& changes);

/// Refuses changes that name a target the rig lacks or would take a mass or a spring to zero
/// or below or a damper below zero at any time (checked at every change's start and end, where
/// the piecewise linear parameters have their extremes). @throws InputError naming `source`,
/// the entry that does it and its add key.
void CheckChanges(const RigSpec& rig, const std::string& source);

/// When the simulator, sampling every dt_s, rebuilds its discrete system, and with which
/// parameters. The system is rebuilt at each step's first tick (the first at or after at_s) and
/// along each drift every 1 % of its duration or every 0.1 s, whichever is finer (never more
/// often than every tick), and at the drift's end; between two rebuilds it holds the exact ramp's
/// value at the interval's middle. So a held parameter is off the ramp by at most half of what
/// the ramp moves in an interval: 0.5 % of the drift's size, or what it moves in 0.05 s when the
/// drift lasts more than 10 s. Why both: 1 % keeps a short drift a ramp rather than a few steps;
/// 0.1 s keeps a drift of hours smooth at the scale a 10 s identification block sees. The cost
/// is bounded: at most 10 rebuilds per simulated second per drift in progress (a rebuild is a
/// few matrix exponentials of a 3n × 3n matrix, tens of microseconds), none once it is over.
class ChangeSchedule {
 public:
  static constexpr std::uint64_t kNever = UINT64_MAX;

  ChangeSchedule() = default;
  ChangeSchedule(std::vector<RigChange> changes, double dt_s);

  /// The first tick after `tick` at which the held parameters change, or kNever.
  std::uint64_t NextRebuild(std::uint64_t tick) const;
  /// The parameters to hold from tick `from` until tick `until` (exclusive; kNever: for good).
  ChainParameters Held(const RigSpec& rig, std::uint64_t from, std::uint64_t until) const;

 private:
  struct Timed {
    RigChange change;
    std::uint64_t first_tick = 0;  ///< the step's tick, or the drift's first
    std::uint64_t last_tick = 0;   ///< the drift's end (the step's tick for a step)
    std::uint64_t every = 1;       ///< ticks between a drift's rebuilds
  };
  std::vector<Timed> timed_;
  double dt_s_ = 0.0;
};

}  // namespace vibid::emu
