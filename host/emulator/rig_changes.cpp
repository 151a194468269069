#include "rig_changes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <utility>

#include "rig.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"

namespace vibid::emu {
namespace {

struct TargetInfo {
  const char* name;     // the file's key: "mass"
  const char* add_key;  // "add_kg"
  const char* unit;     // "kg"
  const char* stays;    // "above 0 kg"
  bool zero_allowed;    // dampers may reach 0, masses and springs may not
};

constexpr std::array<TargetInfo, 3> kTargets{{
    {"mass", "add_kg", "kg", "above 0 kg", false},
    {"spring", "add_n_per_m", "N/m", "above 0 N/m", false},
    {"damper", "add_ns_per_m", "N s/m", "at 0 N s/m or above", true},
}};

const TargetInfo& Info(ChangeTarget t) { return kTargets[static_cast<std::size_t>(t)]; }

std::string Text(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

std::vector<double>& Of(ChainParameters& p, ChangeTarget t) {
  switch (t) {
    case ChangeTarget::kMass: return p.masses_kg;
    case ChangeTarget::kSpring: return p.springs_n_per_m;
    case ChangeTarget::kDamper: break;
  }
  return p.dampers_ns_per_m;
}

ChainParameters Base(const RigSpec& rig) {
  ChainParameters p;
  for (std::size_t i = 0; i < rig.masses_kg.size(); ++i)
    p.masses_kg.push_back(rig.masses_kg[i] * (1.0 - rig.effective_mass_loss[i]));
  p.springs_n_per_m = rig.springs_n_per_m;
  p.dampers_ns_per_m = rig.dampers_ns_per_m;
  return p;
}

// The first tick at or after t_s (a tick's time equal to t_s up to rounding counts as at it).
std::uint64_t TickAtOrAfter(double t_s, double dt_s) {
  const double ticks = std::ceil(t_s / dt_s - 1e-6);
  return ticks >= 1e18 ? ChangeSchedule::kNever : static_cast<std::uint64_t>(std::max(0.0, ticks));
}

}  // namespace

double RigChange::FractionAt(double t_s) const {
  if (t_s < at_s) return 0.0;
  if (over_s <= 0.0) return 1.0;
  return std::min(1.0, (t_s - at_s) / over_s);
}

ChainParameters ParametersAt(const RigSpec& rig, double t_s) {
  ChainParameters p = Base(rig);
  for (const RigChange& c : rig.changes)
    Of(p, c.target)[static_cast<std::size_t>(c.index)] += c.add * c.FractionAt(t_s);
  return p;
}

std::vector<RigChange> ChangesFromJson(const nlohmann::json& list, std::size_t masses,
                                       const std::string& source) {
  Require(list.is_array(), source +
                               ": \"changes\" must be a list of changes: [{\"at_s\": 600, "
                               "\"mass\": 2, \"add_kg\": 0.08}, ...]");
  std::vector<RigChange> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const nlohmann::json& e = list[i];
    const std::string where = source + ": \"changes\"[" + std::to_string(i) + "]";
    Require(e.is_object(), where +
                               " must be an object: {\"at_s\": 600, \"mass\": 2, \"add_kg\": "
                               "0.08} (a step; with \"over_s\", a drift)");
    RequireKnownKeys(
        e, {"at_s", "mass", "spring", "damper", "add_kg", "add_n_per_m", "add_ns_per_m", "over_s"},
        "rig file " + source + " \"changes\"[" + std::to_string(i) + "]");
    const auto number = [&](const char* key) {
      const nlohmann::json& v = e.at(key);
      Require(v.is_number() && std::isfinite(v.get<double>()),
              where + ": \"" + key + "\" must be a finite number");
      return v.get<double>();
    };
    RigChange c;
    Require(e.contains("at_s"),
            where + ": missing \"at_s\" (seconds from the acquisition's start)");
    c.at_s = number("at_s");
    Require(c.at_s >= 0.0,
            where + ": \"at_s\" must be >= 0 (seconds from the acquisition's start)");
    int targets = 0;
    for (std::size_t t = 0; t < kTargets.size(); ++t) {
      if (!e.contains(kTargets[t].name)) continue;
      ++targets;
      c.target = static_cast<ChangeTarget>(t);
    }
    Require(targets == 1,
            where + ": name one target, \"mass\", \"spring\" or \"damper\" (counted from 1)");
    const TargetInfo& info = Info(c.target);
    const nlohmann::json& index = e.at(info.name);
    Require(index.is_number_integer() && index.get<long long>() >= 1 &&
                index.get<long long>() <= static_cast<long long>(masses),
            where + ": \"" + info.name + "\" must be a " + info.name + " of the rig, 1 to " +
                std::to_string(masses));
    c.index = index.get<int>() - 1;
    for (const TargetInfo& other : kTargets) {
      Require(&other == &info || !e.contains(other.add_key),
              where + ": \"" + other.add_key + "\" is a " + other.name + "'s change; a " +
                  info.name + " takes \"" + info.add_key + "\" (" + info.unit + ")");
    }
    Require(e.contains(info.add_key), where + ": missing \"" + info.add_key + "\" (the " +
                                          info.name + "'s change, " + info.unit + ")");
    c.add = number(info.add_key);
    if (e.contains("over_s")) {
      c.over_s = number("over_s");
      Require(c.over_s > 0.0, where +
                                  ": \"over_s\" must be > 0 (a drift's duration, s; leave it out "
                                  "for a step)");
    }
    out.push_back(c);
  }
  return out;
}

nlohmann::json ChangesToJson(const std::vector<RigChange>& changes) {
  nlohmann::json out = nlohmann::json::array();
  for (const RigChange& c : changes) {
    const TargetInfo& info = Info(c.target);
    nlohmann::json e = {{"at_s", c.at_s}, {info.name, c.index + 1}, {info.add_key, c.add}};
    if (c.over_s > 0.0) e["over_s"] = c.over_s;
    out.push_back(e);
  }
  return out;
}

void CheckChanges(const RigSpec& rig, const std::string& source) {
  const auto masses = rig.masses_kg.size();
  for (std::size_t i = 0; i < rig.changes.size(); ++i) {
    const RigChange& c = rig.changes[i];
    const std::string where = source + ": \"changes\"[" + std::to_string(i) + "]";
    Require(c.index >= 0 && static_cast<std::size_t>(c.index) < masses,
            where + ": the rig has no " + Info(c.target).name + " " + std::to_string(c.index + 1));
    Require(std::isfinite(c.at_s) && c.at_s >= 0.0 && std::isfinite(c.add) &&
                std::isfinite(c.over_s) && c.over_s >= 0.0,
            where + ": \"at_s\", the add and \"over_s\" must be finite, the times >= 0");
  }
  // Between the changes' starts and ends every parameter is linear in time, so its extremes are
  // at those times: the value there, and just before (a step there not yet applied).
  std::vector<double> times;
  for (const RigChange& c : rig.changes) {
    times.push_back(c.at_s);
    times.push_back(c.at_s + c.over_s);
  }
  std::sort(times.begin(), times.end());
  const ChainParameters base = Base(rig);
  for (const double t : times) {
    for (const bool before : {true, false}) {
      ChainParameters p = base;
      for (const RigChange& c : rig.changes) {
        const double f = before && c.over_s <= 0.0 && c.at_s == t ? 0.0 : c.FractionAt(t);
        Of(p, c.target)[static_cast<std::size_t>(c.index)] += c.add * f;
      }
      for (std::size_t t_index = 0; t_index < kTargets.size(); ++t_index) {
        const auto target = static_cast<ChangeTarget>(t_index);
        const TargetInfo& info = kTargets[t_index];
        for (std::size_t j = 0; j < masses; ++j) {
          const double v = Of(p, target)[j];
          if (info.zero_allowed ? v >= 0.0 : v > 0.0) continue;
          // Blame the latest change of this parameter that takes something away by then.
          std::size_t culprit = rig.changes.size();
          for (std::size_t i = 0; i < rig.changes.size(); ++i) {
            const RigChange& c = rig.changes[i];
            if (c.target == target && static_cast<std::size_t>(c.index) == j && c.add < 0.0 &&
                c.at_s <= t &&
                (culprit == rig.changes.size() || c.at_s >= rig.changes[culprit].at_s))
              culprit = i;
          }
          throw InputError(source + ": \"changes\"[" + std::to_string(culprit) + "]: \"" +
                           info.add_key + "\" takes " + info.name + " " + std::to_string(j + 1) +
                           " to " + Text(v) + " " + info.unit + " at " + Text(t) + " s; a " +
                           info.name + " must stay " + info.stays);
        }
      }
    }
  }
}

ChangeSchedule::ChangeSchedule(std::vector<RigChange> changes, double dt_s) : dt_s_(dt_s) {
  for (RigChange& c : changes) {
    Timed t;
    t.first_tick = TickAtOrAfter(c.at_s, dt_s);
    t.last_tick = c.over_s > 0.0 ? TickAtOrAfter(c.at_s + c.over_s, dt_s) : t.first_tick;
    if (c.over_s > 0.0) {
      const double every_s = std::min(0.01 * c.over_s, 0.1);
      t.every = static_cast<std::uint64_t>(std::max(1.0, std::floor(every_s / dt_s + 1e-6)));
    }
    t.change = std::move(c);
    timed_.push_back(t);
  }
}

std::uint64_t ChangeSchedule::NextRebuild(std::uint64_t tick) const {
  std::uint64_t next = kNever;
  for (const Timed& t : timed_) {
    std::uint64_t candidate = kNever;
    if (tick < t.first_tick) {
      candidate = t.first_tick;
    } else if (tick < t.last_tick) {
      candidate =
          std::min(t.last_tick, t.first_tick + ((tick - t.first_tick) / t.every + 1) * t.every);
    }
    next = std::min(next, candidate);
  }
  return next;
}

ChainParameters ChangeSchedule::Held(const RigSpec& rig, std::uint64_t from,
                                     std::uint64_t until) const {
  ChainParameters p = Base(rig);
  // Every change's breakpoints are rebuild ticks, so over [from, until) a step is either in force
  // throughout or not at all, and a drift is linear: its value at the interval's middle is the
  // held value closest to the ramp. Held for good (until kNever), every drift is over.
  const double middle_s =
      until == kNever ? 0.0
                      : 0.5 * (static_cast<double>(from) + static_cast<double>(until)) * dt_s_;
  for (const Timed& t : timed_) {
    const RigChange& c = t.change;
    double f = from >= t.last_tick ? 1.0 : 0.0;  // a step, or a drift that is over
    if (c.over_s > 0.0 && from < t.last_tick && until > t.first_tick) f = c.FractionAt(middle_s);
    Of(p, c.target)[static_cast<std::size_t>(c.index)] += c.add * f;
  }
  return p;
}

}  // namespace vibid::emu
