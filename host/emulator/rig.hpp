// The simulated rig: a series chain of one to four masses on springs (methods §1, rig A), its true
// parameters, Coulomb friction per mass, the board's response inputs (two accelerometers, two
// encoders) each mounted on a mass, and the excitations of the scenarios. Everything the host is
// meant to discover lives here and only here.
//
// Stepping is exact for the linear part: the state advances by the zero-order-hold
// discretization of (M, C, K) at the sample period (vibid::model::Discretize), with the applied
// forces, the friction force included, held over each sample. Each channel is read at the
// board's own sampling instant after tick k's edge (board_profile.hpp: force1, acc1, acc2 and
// the encoders 2.667 us after it, force2 5.905 us): a response is the state advanced
// exactly from the edge to that instant under the held forces (the same zero-order hold over a
// part of the step), a load cell reads the force held over the step, and a tone on the analog
// inputs (scenario tone) is evaluated at each channel's instant. Then the values are quantized
// like the board's converters. The excitation and the noise come from one generator seeded from the
// rig seed and the acquisition count, so the same seed and the same commands give the same samples.
// A rig file's "changes" (rig_changes.hpp) change the masses, springs and dampers during each
// acquisition: the discrete system is rebuilt from the changed model at the ticks the change
// schedule names, the state carrying over.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "emu_port.hpp"
#include "operate_force.hpp"
#include "rig_changes.hpp"
#include "vibid/model/model.hpp"
#include "vibid/model/state_space.hpp"
#include "vibid/shared/wire/device.hpp"

namespace vibid::emu {

/// One analog channel: bipolar range ±range around the converter's mid code, white noise of the
/// given RMS added before quantization, `adc_bits` of resolution (raw codes 0 .. 2^bits − 1).
struct AnalogSensor {
  double range = 0.0;      ///< full scale, SI units (N or m/s²)
  double noise_rms = 0.0;  ///< SI units
  int adc_bits = 12;

  /// Raw ADC code for a physical value (clipped at the converter's ends).
  std::int32_t Code(double value) const;
  /// The physical value a code stands for (inverse of Code without noise and clipping).
  double Value(std::int32_t code) const;
};

/// The most masses a rig may have: the board has four response inputs (acc1, acc2, x1, x2) and
/// every mass must be measured by one of them.
inline constexpr int kMaxMasses = 4;

/// The board's response inputs, in wire::Channel order from channel 2: acc1, acc2, x1, x2.
inline constexpr std::array<const char*, 4> kResponseInputNames{"acc1", "acc2", "x1", "x2"};
/// Marks a response input mounted on no mass (it reads the rig at rest: mid code plus its
/// converter's noise, or encoder count 0).
inline constexpr int kUnmounted = -1;

struct RigSpec {
  /// Plate masses as built; the dynamics use masses_kg · (1 − effective_mass_loss) (methods §6).
  std::vector<double> masses_kg;
  std::vector<double> effective_mass_loss;
  std::vector<double> springs_n_per_m;
  std::vector<double> dampers_ns_per_m;
  std::vector<double> coulomb_n;                 ///< Coulomb friction force per mass (guide), N
  std::array<AnalogSensor, 2> load_cells{};      ///< hammer/shaker/pull, hand push
  std::array<AnalogSensor, 2> accelerometers{};  ///< acc1, acc2 (mounted per `input_mass`)
  double encoder_counts_per_m = 0.0;
  /// The 0-based mass each response input (acc1, acc2, x1, x2) is mounted on, or kUnmounted.
  /// Rig file key "response_inputs": {"acc1": 1, "x1": 3, ...} (masses from 1; an input left out
  /// is unmounted); without it, a rig of one or two masses has acc<i> and x<i> on mass i.
  std::array<int, 4> input_mass{0, 1, 0, 1};
  /// The 0-based mass the hammer scenario hits when its mass parameter is 0 (rig file key
  /// "hammer_mass", from 1, optional); kUnmounted: the last mass.
  int hammer_mass = kUnmounted;
  double max_sample_rate_hz = 0.0;
  /// The emulated board's option bytes: its brown-out reset level (get-info's health page,
  /// self-test). Rig file key "brown_out_level" ("level3", "level2", "level1", "off"), optional.
  wire::BrownOut brown_out = wire::BrownOut::kLevel3;
  /// Hits of the hammer scenario made faulty on purpose, counted from 1 in each acquisition (rig
  /// file key "hammer_test_hits": {"double_hit": [k...], "overload": [j...]}, optional): a double
  /// hit strikes again 15 ms after its start at 60 % of its height; an overload is a blow of twice
  /// the hammer load cell's range, which its converter clips at its top code as the board's does.
  std::vector<int> double_hits;
  std::vector<int> overloads;
  /// Steps and drifts of the masses, springs and dampers during each acquisition, timed from
  /// its start (rig file key "changes", optional; rig_changes.hpp).
  std::vector<RigChange> changes;

  int dofs() const { return static_cast<int>(masses_kg.size()); }
  /// The rig's truth at an acquisition's start: the chain with the effective masses.
  model::Model Truth() const { return TruthAt(0.0); }
  /// The truth t_s after an acquisition's start, with the changes in force then (the exact
  /// ramps; the simulator holds them as ChangeSchedule says).
  model::Model TruthAt(double t_s) const;
};

/// The built-in rig: the shipped nominal model (examples/rig_nominal.json: m = 2.0, 1.5 kg,
/// k = 4000, 3000 N/m) as the real rig turned out: m1 effectively 9 % lighter (it rocks on its
/// carriage), m2 2 % heavier, springs 12 % and 8 % softer, light damping and guide friction.
RigSpec DefaultRig();

/// Reads a rig file. @throws InputError naming `source` and the offending field.
RigSpec RigFromJson(const nlohmann::json& json, const std::string& source = "rig");
RigSpec LoadRig(const std::string& path);
nlohmann::json RigToJson(const RigSpec& rig);
/// The truth as a model file (chain form with the effective masses), for comparisons: at an
/// acquisition's start, or t_s after it with the rig's changes in force then.
nlohmann::json TruthToJson(const RigSpec& rig, double t_s = 0.0);

/// Which masses move: the chain, or one mass alone on its own spring to ground (the mass tests).
enum class Configuration : std::uint8_t {
  kChain = 0,
  kMass1Alone = 1,
  kMass2Alone = 2,
  kMass3Alone = 3,
  kMass4Alone = 4
};

/// The 0-based mass a configuration leaves alone on its spring, or kUnmounted for the chain.
inline int AloneMass(Configuration c) { return static_cast<int>(c) - 1; }

enum class ScenarioKind : std::uint8_t { kIdle, kHammer, kShaker, kPush, kStep, kTone, kOperate };

/// A selected excitation; see ParseScenario for the wire parameters.
struct Scenario {
  ScenarioKind kind = ScenarioKind::kIdle;
  Configuration configuration = Configuration::kChain;
  int mass = 1;  ///< 0-based mass the hammer hits / the pull acts on / operation drives
  /// hammer peak, shaker amplitude, push amplitude, pull force, operation's RMS force
  double force_n = 0.0;
  double spacing_s = 0.0;  ///< hammer: mean time between hits (0: DefaultHammerSpacingS)
  /// shaker's frequency, tone's; operate: the force's upper band edge (0: DefaultOperateBandHz)
  double frequency_hz = 0.0;
  double push_n = 0.0;     ///< shaker, operate: amplitude of the simultaneous hand push (0: none)
  double hold_s = 0.0;     ///< step: how long the pull holds before the release
  double amplitude = 0.0;  ///< tone: fraction of each converter's range
};

/// The hammer's mean hit spacing when the scenario leaves it open: the shortest spacing (0.7 of
/// the mean) lets the slowest mode of `active` ring down to 1 % (ln 100 / (zeta omega)), rounded
/// up to 0.5 s, at most 60 s. Why: each hit's record runs to the next hit, so the record holds
/// the hit's whole response and its lines (1 / record apart) resolve the mode's half-power band;
/// hits closer than that give records a modal analysis cannot use (12.5 s for the built-in
/// chain, 5 s and 6 s for its masses alone).
double DefaultHammerSpacingS(const model::Model& active);

/// The operate scenario's band edge when the scenario leaves it open: 50 Hz, or twice the
/// highest undamped mode of `active` when that is higher, so every mode lies well inside the
/// band (the force is flat there) and the observer sees the disturbance its band passes.
double DefaultOperateBandHz(const model::Model& active);

/// The rig behind the emulated board's converters (the port's SimulatedRig).
class RigSimulator final : public SimulatedRig {
 public:
  RigSimulator(RigSpec spec, std::uint64_t seed);

  const RigSpec& spec() const { return spec_; }
  const Scenario& scenario() const { return scenario_; }

  /// Selects the excitation (and the moving masses) for the next Start.
  void Select(const Scenario& scenario);

  /// select-scenario from the wire: parsed against this rig's masses, then selected.
  Status SelectScenario(const wire::ScenarioRequest& request, wire::Refusal& why) override;
  double MaxSampleRateHz() const override { return spec_.max_sample_rate_hz; }

  /// Puts the rig at rest and restarts the excitation for a new acquisition at dt_s.
  void Start(double dt_s) override;

  /// One sample: the six raw channel values at the current tick, then the state advances.
  void Step(std::array<std::int32_t, wire::kChannelCount>& raw) override;

  /// Physical values at the last Step (for tests): applied excitation force, push force, and
  /// per mass (0-based, 0 for a mass that does not move) the true position at the encoders'
  /// instant and acceleration at the accelerometers' instant.
  struct Truths {
    double force_n = 0.0;
    double push_n = 0.0;
    std::array<double, kMaxMasses> x_m{};
    std::array<double, kMaxMasses> a_m_s2{};
  };
  const Truths& last() const { return last_; }

  /// The model the current configuration simulates at an acquisition's start (1×1 for a mass
  /// alone).
  model::Model ActiveModel() const;
  /// The model the discrete system was last built from (after Start: the one the next Step
  /// uses): the changes held as ChangeSchedule says, for tests.
  const model::Model& HeldModel() const { return held_; }
  /// Positions (m) then velocities (m/s) of the moving masses at the next Step's tick edge, for
  /// tests.
  const Eigen::VectorXd& state() const { return state_; }

 private:
  model::Model ConfigurationModel(const ChainParameters& p) const;
  /// Builds the discrete system and the part steps from the parameters held from tick_ on.
  void Rebuild();
  void Excitation(double t_s, double& force_n, double& push_n);
  double Noise(double rms);

  RigSpec spec_;
  std::uint64_t seed_;
  std::uint64_t starts_ = 0;
  Scenario scenario_{};
  double dt_s_ = 0.0;
  std::uint64_t tick_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};

  // Active configuration: indices of the moving masses and its discrete system, built from
  // held_ and rebuilt at the tick next_rebuild_ (the change schedule's).
  std::vector<int> moving_;
  ChangeSchedule schedule_;
  std::uint64_t next_rebuild_ = ChangeSchedule::kNever;
  model::Model held_;
  model::StateSpace discrete_;
  // Each channel's sampling instant after the edge (s), and the zero-order-hold step from the
  // edge to every distinct one of them.
  std::array<double, wire::kChannelCount> instant_s_{};
  std::vector<std::pair<double, model::StateSpace>> part_steps_;
  // The rig's outputs (positions, velocities, accelerations of the moving masses) at each
  // distinct instant after the current tick's edge, under the forces held from it; index 0 is
  // the edge itself (output_), index 1 + i part_steps_[i]. Which one each channel reads, and
  // the row in it of each response input (-1: its mass does not move).
  std::vector<Eigen::VectorXd> part_outputs_;
  std::array<std::size_t, wire::kChannelCount> channel_outputs_{};
  std::array<Eigen::Index, 4> input_row_{};
  std::array<Eigen::Index, kMaxMasses> x_row_{}, a_row_{};
  Eigen::VectorXd part_state_;
  Eigen::VectorXd state_;
  Eigen::VectorXd input_;
  Eigen::VectorXd output_;

  // Hammer: pulses in flight and the next hit.
  struct Pulse {
    double start_s;
    double width_s;
    double height_n;
  };
  std::vector<Pulse> pulses_;
  double next_hit_s_ = 0.0;
  int hits_ = 0;  // hammer hits struck since Start
  // Hand push: a few slow sinusoids (0.2–2 Hz) making a one-sided push.
  std::array<double, 4> push_freq_hz_{};
  std::array<double, 4> push_phase_{};
  // Operate: the band-limited random force.
  BandLimitedNoise operate_force_;

  Truths last_{};
};

}  // namespace vibid::emu
