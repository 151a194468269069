#include "rig.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <stdexcept>

#include "scenario.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::emu {
namespace {

constexpr double kPi = std::numbers::pi;
/// Hammer tip contact time: a 2 ms half-sine excites evenly up to a few hundred hertz.
constexpr double kHammerPulseS = 0.002;
/// Quiet time before the first hit or pull, so a pre-trigger sees the rig at rest.
constexpr double kFirstEventS = 0.5;
/// Below this speed the friction force is proportional to it: a Coulomb law held over a sample
/// would otherwise chatter around zero velocity.
constexpr double kStictionSpeedMPerS = 1e-4;

std::vector<double> NumberArray(const nlohmann::json& json, const char* key,
                                const std::string& source, std::size_t count, bool positive) {
  Require(json.contains(key), source + ": missing \"" + key + "\"");
  const auto& a = json.at(key);
  Require(a.is_array() && a.size() == count,
          source + ": \"" + key + "\" must be an array of " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (const auto& v : a) {
    Require(v.is_number(), source + ": \"" + key + "\" holds a non-number");
    const double x = v.get<double>();
    Require(std::isfinite(x) && (positive ? x > 0.0 : x >= 0.0),
            source + ": \"" + key + "\" values must be " + (positive ? "> 0" : ">= 0"));
    out.push_back(x);
  }
  return out;
}

double Number(const nlohmann::json& json, const char* key, const std::string& source) {
  Require(json.contains(key) && json.at(key).is_number(),
          source + ": missing number \"" + key + "\"");
  const double x = json.at(key).get<double>();
  Require(std::isfinite(x) && x > 0.0, source + ": \"" + key + "\" must be > 0");
  return x;
}

AnalogSensor SensorFromJson(const nlohmann::json& json, const char* range_key,
                            const char* noise_key, const std::string& source) {
  Require(json.is_object(), source + " must be an object");
  RequireKnownKeys(json, {range_key, noise_key, "adc_bits"}, "rig file " + source);
  AnalogSensor s;
  s.range = Number(json, range_key, source);
  Require(json.contains(noise_key) && json.at(noise_key).is_number() &&
              json.at(noise_key).get<double>() >= 0.0,
          source + ": \"" + noise_key + "\" must be a number >= 0");
  s.noise_rms = json.at(noise_key).get<double>();
  Require(json.contains("adc_bits") && json.at("adc_bits").is_number_integer(),
          source + ": missing integer \"adc_bits\"");
  const std::int64_t bits = json.at("adc_bits").get<std::int64_t>();
  // The emulator is the board: its converters are the board's, and the log's 12.4 format holds
  // their codes and no more (a wider code would sit at the format's top, every sample clipped).
  Require(bits == kBoardProfile.adc_bits,
          source + ": \"adc_bits\" is " + std::to_string(bits) +
              ", but the board's converters have " + std::to_string(kBoardProfile.adc_bits) +
              " bits: write " + std::to_string(kBoardProfile.adc_bits) +
              " (a finer sensor is quantized by the board's ADC)");
  s.adc_bits = static_cast<int>(bits);
  return s;
}

std::array<AnalogSensor, 2> SensorPair(const nlohmann::json& json, const char* key,
                                       const char* range_key, const char* noise_key,
                                       const std::string& source) {
  Require(json.contains(key) && json.at(key).is_array() && json.at(key).size() == 2,
          source + ": \"" + key + "\" must be an array of 2 sensors");
  return {SensorFromJson(json.at(key)[0], range_key, noise_key, source + " " + key + "[0]"),
          SensorFromJson(json.at(key)[1], range_key, noise_key, source + " " + key + "[1]")};
}

// "response_inputs": {"acc1": 1, "x1": 3, ...}, the mass (from 1) each of the board's response
// inputs is mounted on; every mass needs one. Left out: acc<i> and x<i> on mass i (1 or 2 masses).
std::array<int, 4> ResponseInputs(const nlohmann::json& json, std::size_t masses,
                                  const std::string& source) {
  const std::string where = source + ": \"response_inputs\"";
  std::array<int, 4> out{kUnmounted, kUnmounted, kUnmounted, kUnmounted};
  if (!json.contains("response_inputs")) {
    Require(masses <= 2, source + ": a rig of " + std::to_string(masses) +
                             " masses names the response input on each mass: "
                             "\"response_inputs\": {\"acc1\": 1, \"acc2\": 2, \"x1\": 3, ...} "
                             "(inputs acc1, acc2, x1, x2; masses from 1)");
    for (std::size_t i = 0; i < masses; ++i) {
      out[i] = static_cast<int>(i);      // acc<i+1>
      out[2 + i] = static_cast<int>(i);  // x<i+1>
    }
    return out;
  }
  const nlohmann::json& inputs = json.at("response_inputs");
  Require(inputs.is_object() && !inputs.empty(),
          where + " must be an object naming inputs: {\"acc1\": 1, \"x1\": 2, ...}");
  RequireKnownKeys(inputs, {"acc1", "acc2", "x1", "x2"}, "rig file " + source + " response_inputs");
  for (std::size_t c = 0; c < kResponseInputNames.size(); ++c) {
    const char* name = kResponseInputNames[c];
    if (!inputs.contains(name)) continue;
    const nlohmann::json& m = inputs.at(name);
    Require(
        m.is_number_integer() && m.get<long long>() >= 1 &&
            m.get<long long>() <= static_cast<long long>(masses),
        where + ": \"" + name + "\" must name a mass of the rig, 1 to " + std::to_string(masses));
    out[c] = m.get<int>() - 1;
  }
  for (std::size_t i = 0; i < masses; ++i) {
    Require(std::find(out.begin(), out.end(), static_cast<int>(i)) != out.end(),
            where + ": no input measures mass " + std::to_string(i + 1) +
                " (each mass needs one of acc1, acc2, x1, x2)");
  }
  return out;
}

std::string FormatRate(double hz) {
  std::ostringstream o;
  o << hz << " Hz";
  return o.str();
}

nlohmann::json SensorToJson(const AnalogSensor& s, const char* range_key, const char* noise_key) {
  return {{range_key, s.range}, {noise_key, s.noise_rms}, {"adc_bits", s.adc_bits}};
}

}  // namespace

std::int32_t AnalogSensor::Code(double value) const {
  const double half = std::ldexp(1.0, adc_bits - 1);
  const double code = std::round(value / range * half) + half;
  return static_cast<std::int32_t>(std::clamp(code, 0.0, 2.0 * half - 1.0));
}

double AnalogSensor::Value(std::int32_t code) const {
  const double half = std::ldexp(1.0, adc_bits - 1);
  return (static_cast<double>(code) - half) * range / half;
}

model::Model RigSpec::TruthAt(double t_s) const {
  const ChainParameters p = ParametersAt(*this, t_s);
  return model::MakeChain(Eigen::Map<const Eigen::VectorXd>(p.masses_kg.data(), dofs()),
                          Eigen::Map<const Eigen::VectorXd>(p.springs_n_per_m.data(), dofs()),
                          Eigen::Map<const Eigen::VectorXd>(p.dampers_ns_per_m.data(), dofs()));
}

RigSpec DefaultRig() {
  RigSpec r;
  r.masses_kg = {2.0, 1.53};             // plate stacks: m1 as specified, m2 +2 %
  r.effective_mass_loss = {0.09, 0.0};   // m1 behaves 9 % lighter: 1.82 kg
  r.springs_n_per_m = {3520.0, 2760.0};  // 4000 −12 %, 3000 −8 %
  r.dampers_ns_per_m = {5.0, 3.5};
  r.coulomb_n = {0.005, 0.005};  // guide friction of a low-friction carriage, 5 mN
  r.load_cells = {AnalogSensor{500.0, 0.1, 12}, AnalogSensor{50.0, 0.01, 12}};
  r.accelerometers = {AnalogSensor{200.0, 0.05, 12}, AnalogSensor{200.0, 0.05, 12}};
  r.encoder_counts_per_m = 100000.0;  // 10 µm per count
  r.max_sample_rate_hz = 10000.0;
  return r;
}

RigSpec RigFromJson(const nlohmann::json& json, const std::string& source) {
  Require(json.is_object(), source + ": expected a JSON object");
  RequireKnownKeys(
      json,
      {"topology", "masses_kg", "effective_mass_loss", "springs_n_per_m", "dampers_ns_per_m",
       "coulomb_n", "load_cells", "accelerometers", "encoder_counts_per_m", "max_sample_rate_hz",
       "brown_out_level", "hammer_test_hits", "response_inputs", "hammer_mass", "changes"},
      "rig file " + source);
  // Compared as a JSON value: a topology of another type is a wrong value, not a type error.
  Require(json.value("topology", nlohmann::json()) == "chain",
          source + ": \"topology\" must be \"chain\" (masses in series from ground)");
  RigSpec r;
  Require(json.contains("masses_kg") && json.at("masses_kg").is_array(),
          source + ": missing \"masses_kg\"");
  const std::size_t n = json.at("masses_kg").size();
  Require(n >= 1 && n <= static_cast<std::size_t>(kMaxMasses),
          source + ": the rig has 1 to " + std::to_string(kMaxMasses) +
              " masses (the board has four response inputs, acc1, acc2, x1, x2, and each mass "
              "needs one)");
  r.masses_kg = NumberArray(json, "masses_kg", source, n, true);
  r.springs_n_per_m = NumberArray(json, "springs_n_per_m", source, n, true);
  r.dampers_ns_per_m = NumberArray(json, "dampers_ns_per_m", source, n, false);
  r.coulomb_n = NumberArray(json, "coulomb_n", source, n, false);
  r.effective_mass_loss = NumberArray(json, "effective_mass_loss", source, n, false);
  for (double loss : r.effective_mass_loss) {
    Require(loss < 0.5,
            source + ": \"effective_mass_loss\" must be below 0.5 (a fraction of the mass)");
  }
  r.input_mass = ResponseInputs(json, n, source);
  if (json.contains("hammer_mass")) {
    const nlohmann::json& h = json.at("hammer_mass");
    Require(h.is_number_integer() && h.get<long long>() >= 1 &&
                h.get<long long>() <= static_cast<long long>(n),
            source + ": \"hammer_mass\" must be a mass of the rig, 1 to " + std::to_string(n));
    r.hammer_mass = h.get<int>() - 1;
  }
  r.load_cells = SensorPair(json, "load_cells", "range_n", "noise_n", source);
  r.accelerometers = SensorPair(json, "accelerometers", "range_m_s2", "noise_m_s2", source);
  r.encoder_counts_per_m = Number(json, "encoder_counts_per_m", source);
  r.max_sample_rate_hz = Number(json, "max_sample_rate_hz", source);
  const double board_max_hz = kBoardProfile.max_sample_rate_hz();
  Require(r.max_sample_rate_hz <= board_max_hz,
          source + ": \"max_sample_rate_hz\" is " + FormatRate(r.max_sample_rate_hz) +
              ", but the board samples at " + FormatRate(board_max_hz) + " at most: write " +
              FormatRate(board_max_hz) + " or less");
  if (json.contains("brown_out_level")) {
    const nlohmann::json& level = json.at("brown_out_level");
    const std::pair<const char*, wire::BrownOut> levels[] = {{"level3", wire::BrownOut::kLevel3},
                                                             {"level2", wire::BrownOut::kLevel2},
                                                             {"level1", wire::BrownOut::kLevel1},
                                                             {"off", wire::BrownOut::kOff}};
    bool known = false;
    for (const auto& [name, value] : levels) {
      if (level == name) {
        r.brown_out = value;
        known = true;
      }
    }
    Require(known, source +
                       ": \"brown_out_level\" must be \"level3\", \"level2\", \"level1\" or "
                       "\"off\" (the option bytes' BOR_LEV)");
  }
  if (json.contains("hammer_test_hits")) {
    const nlohmann::json& h = json.at("hammer_test_hits");
    const std::string where = "rig file " + source + ", \"hammer_test_hits\"";
    Require(h.is_object(), where + ": expected {\"double_hit\": [k...], \"overload\": [j...]}");
    RequireKnownKeys(h, {"double_hit", "overload"}, where);
    const auto hits = [&](const char* key) {
      std::vector<int> out;
      if (!h.contains(key)) return out;
      const nlohmann::json& list = h.at(key);
      Require(list.is_array(), where + ": \"" + key + "\" must be a list of hit numbers");
      for (const nlohmann::json& k : list) {
        Require(k.is_number_integer() && k.get<long long>() >= 1 && k.get<long long>() <= 100000,
                where + ": \"" + key +
                    "\" holds hit numbers from 1 (the first hit of an "
                    "acquisition is 1)");
        out.push_back(k.get<int>());
      }
      return out;
    };
    r.double_hits = hits("double_hit");
    r.overloads = hits("overload");
  }
  if (json.contains("changes")) {
    r.changes = ChangesFromJson(json.at("changes"), n, source);
    CheckChanges(r, source);
  }
  return r;
}

RigSpec LoadRig(const std::string& path) { return RigFromJson(ReadJsonFile(path), path); }

nlohmann::json RigToJson(const RigSpec& r) {
  nlohmann::json j = {{"topology", "chain"},
                      {"masses_kg", r.masses_kg},
                      {"effective_mass_loss", r.effective_mass_loss},
                      {"springs_n_per_m", r.springs_n_per_m},
                      {"dampers_ns_per_m", r.dampers_ns_per_m},
                      {"coulomb_n", r.coulomb_n},
                      {"load_cells",
                       {SensorToJson(r.load_cells[0], "range_n", "noise_n"),
                        SensorToJson(r.load_cells[1], "range_n", "noise_n")}},
                      {"accelerometers",
                       {SensorToJson(r.accelerometers[0], "range_m_s2", "noise_m_s2"),
                        SensorToJson(r.accelerometers[1], "range_m_s2", "noise_m_s2")}},
                      {"encoder_counts_per_m", r.encoder_counts_per_m},
                      {"max_sample_rate_hz", r.max_sample_rate_hz},
                      {"brown_out_level", r.brown_out == wire::BrownOut::kLevel2   ? "level2"
                                          : r.brown_out == wire::BrownOut::kLevel1 ? "level1"
                                          : r.brown_out == wire::BrownOut::kOff    ? "off"
                                                                                   : "level3"}};
  nlohmann::json inputs = nlohmann::json::object();
  for (std::size_t c = 0; c < kResponseInputNames.size(); ++c) {
    if (r.input_mass[c] != kUnmounted) inputs[kResponseInputNames[c]] = r.input_mass[c] + 1;
  }
  j["response_inputs"] = inputs;
  if (r.hammer_mass != kUnmounted) j["hammer_mass"] = r.hammer_mass + 1;
  // Only a rig that asks for test hits names them: a rig file as before stays as it was.
  if (!r.double_hits.empty() || !r.overloads.empty())
    j["hammer_test_hits"] = {{"double_hit", r.double_hits}, {"overload", r.overloads}};
  if (!r.changes.empty()) j["changes"] = ChangesToJson(r.changes);
  return j;
}

nlohmann::json TruthToJson(const RigSpec& r, double t_s) {
  const ChainParameters p = ParametersAt(r, t_s);
  return {{"topology", "chain"},
          {"masses", p.masses_kg},
          {"springs", p.springs_n_per_m},
          {"dampers", p.dampers_ns_per_m}};
}

RigSimulator::RigSimulator(RigSpec spec, std::uint64_t seed) : spec_(std::move(spec)), seed_(seed) {
  CheckChanges(spec_, "rig");
  (void)spec_.Truth();  // validates
  Require(spec_.dofs() >= 1 && spec_.dofs() <= kMaxMasses,
          "the rig has 1 to " + std::to_string(kMaxMasses) + " masses");
  for (std::size_t c = 0; c < spec_.input_mass.size(); ++c) {
    Require(spec_.input_mass[c] == kUnmounted ||
                (spec_.input_mass[c] >= 0 && spec_.input_mass[c] < spec_.dofs()),
            std::string("response input ") + kResponseInputNames[c] + " is on no mass of the rig");
  }
  Require(spec_.hammer_mass == kUnmounted ||
              (spec_.hammer_mass >= 0 && spec_.hammer_mass < spec_.dofs()),
          "the hammer's mass is no mass of the rig");
  for (std::size_t c = 0; c < wire::kChannelCount; ++c)
    instant_s_[c] = kBoardProfile.sample_instant_ns(c) * 1e-9;
}

double DefaultHammerSpacingS(const model::Model& active) {
  constexpr double kLongestS = 60.0;
  const model::ComplexModes modes = model::ComplexModalDamping(active);
  double ring_down_s = 0.0;
  for (Eigen::Index i = 0; i < modes.omega_rad_s.size(); ++i) {
    const double decay_rate = modes.zeta[i] * modes.omega_rad_s[i];
    ring_down_s = decay_rate > 0.0 ? std::max(ring_down_s, std::log(100.0) / decay_rate)
                                   : std::numeric_limits<double>::infinity();
  }
  return std::min(kLongestS, std::ceil(ring_down_s / 0.7 * 2.0) / 2.0);
}

double DefaultOperateBandHz(const model::Model& active) {
  return std::max(50.0, 2.0 * model::Modal(active).freq_hz.maxCoeff());
}

void RigSimulator::Select(const Scenario& scenario) {
  scenario_ = scenario;
  if (scenario_.kind == ScenarioKind::kHammer && scenario_.spacing_s == 0.0)
    scenario_.spacing_s = DefaultHammerSpacingS(ActiveModel());
  if (scenario_.kind == ScenarioKind::kOperate && scenario_.frequency_hz == 0.0)
    scenario_.frequency_hz = DefaultOperateBandHz(ActiveModel());
}

Status RigSimulator::SelectScenario(const wire::ScenarioRequest& request, wire::Refusal& why) {
  Scenario s;
  if (const Status st = ParseScenario(request, spec_.dofs(), s, &why, spec_.hammer_mass);
      st != Status::kOk)
    return st;
  Select(s);
  return Status::kOk;
}

model::Model RigSimulator::ActiveModel() const {
  return ConfigurationModel(ParametersAt(spec_, 0.0));
}

model::Model RigSimulator::ConfigurationModel(const ChainParameters& p) const {
  const auto n = static_cast<Eigen::Index>(p.masses_kg.size());
  if (scenario_.configuration == Configuration::kChain) {
    return model::MakeChain(Eigen::Map<const Eigen::VectorXd>(p.masses_kg.data(), n),
                            Eigen::Map<const Eigen::VectorXd>(p.springs_n_per_m.data(), n),
                            Eigen::Map<const Eigen::VectorXd>(p.dampers_ns_per_m.data(), n));
  }
  // One mass alone on its own spring and dashpot to ground.
  const int i = AloneMass(scenario_.configuration);
  Require(i >= 0 && i < spec_.dofs(), "the configuration leaves alone a mass the rig lacks");
  const auto u = static_cast<std::size_t>(i);
  Eigen::VectorXd m(1), k(1), c(1);
  m(0) = p.masses_kg[u];
  k(0) = p.springs_n_per_m[u];
  c(0) = p.dampers_ns_per_m[u];
  return model::MakeChain(m, k, c);
}

void RigSimulator::Rebuild() {
  // Each rebuild holds the parameters until the next one; the state (positions, velocities)
  // carries over as it is. So a mass put on at a step keeps the cart's position and velocity:
  // a hand places it on the moving cart and brings it to the cart's speed, so momentum is not
  // conserved (the hand supplies the difference); the acceleration changes at once to the
  // forces over the new mass.
  next_rebuild_ = schedule_.NextRebuild(tick_);
  held_ = ConfigurationModel(schedule_.Held(spec_, tick_, next_rebuild_));
  const model::StateSpace continuous = model::ModelStateSpace(held_);
  discrete_ = model::Discretize(continuous, dt_s_);
  part_steps_.clear();
  for (double instant : instant_s_) {
    const bool known = std::any_of(part_steps_.begin(), part_steps_.end(),
                                   [&](const auto& p) { return p.first == instant; });
    // An instant is well inside any period the board allows (100 us and up).
    Require(instant < dt_s_, "sampling instant beyond the sample period");
    if (!known && instant > 0.0)
      part_steps_.emplace_back(instant, model::Discretize(continuous, instant));
  }
}

void RigSimulator::Start(double dt_s) {
  dt_s_ = dt_s;
  tick_ = 0;
  ++starts_;
  // splitmix-style mixing so neighbouring seeds and acquisition counts give unrelated streams
  std::uint64_t z = seed_ + 0x9E3779B97F4A7C15ull * starts_;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  rng_.seed(z ^ (z >> 31));
  normal_.reset();

  moving_.clear();
  if (scenario_.configuration == Configuration::kChain) {
    for (int i = 0; i < spec_.dofs(); ++i) moving_.push_back(i);
  } else {
    moving_.push_back(AloneMass(scenario_.configuration));
  }
  schedule_ = ChangeSchedule(spec_.changes, dt_s);
  Rebuild();
  const auto n = static_cast<Eigen::Index>(moving_.size());
  state_ = Eigen::VectorXd::Zero(2 * n);
  input_ = Eigen::VectorXd::Zero(n);
  output_ = Eigen::VectorXd::Zero(3 * n);
  part_outputs_.assign(1 + part_steps_.size(), Eigen::VectorXd::Zero(3 * n));
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    channel_outputs_[c] = 0;
    for (std::size_t p = 0; p < part_steps_.size(); ++p) {
      if (part_steps_[p].first == instant_s_[c]) channel_outputs_[c] = 1 + p;
    }
  }
  // Rows of the outputs (positions 0..n-1, velocities n..2n-1, accelerations 2n..3n-1) each
  // response input and each mass's truths read; -1 for a mass that does not move.
  const auto row_of = [&](int mass) -> Eigen::Index {
    const auto at = std::find(moving_.begin(), moving_.end(), mass);
    return at == moving_.end() ? -1 : static_cast<Eigen::Index>(at - moving_.begin());
  };
  for (std::size_t c = 0; c < input_row_.size(); ++c) {
    const Eigen::Index j = spec_.input_mass[c] == kUnmounted ? -1 : row_of(spec_.input_mass[c]);
    input_row_[c] = j < 0 ? -1 : (c < 2 ? 2 * n + j : j);  // acc1, acc2, then x1, x2
  }
  for (int mass = 0; mass < kMaxMasses; ++mass) {
    const Eigen::Index j = row_of(mass);
    x_row_[static_cast<std::size_t>(mass)] = j;
    a_row_[static_cast<std::size_t>(mass)] = j < 0 ? -1 : 2 * n + j;
  }

  pulses_.clear();
  next_hit_s_ = kFirstEventS;
  hits_ = 0;
  std::uniform_real_distribution<double> freq(0.2, 2.0), phase(0.0, 2.0 * kPi);
  for (std::size_t i = 0; i < push_freq_hz_.size(); ++i) {
    push_freq_hz_[i] = freq(rng_);
    push_phase_[i] = phase(rng_);
  }
  if (scenario_.kind == ScenarioKind::kOperate)
    operate_force_.Start(scenario_.force_n, scenario_.frequency_hz, 1.0 / dt_s);
  last_ = {};
}

double RigSimulator::Noise(double rms) { return rms > 0.0 ? rms * normal_(rng_) : 0.0; }

void RigSimulator::Excitation(double t, double& force_n, double& push_n) {
  force_n = 0.0;
  push_n = 0.0;
  const Scenario& s = scenario_;
  auto hand_push = [&](double amplitude) {
    // One-sided (a hand only pushes), faded in over the first second from zero.
    double sum = 0.0;
    for (std::size_t i = 0; i < push_freq_hz_.size(); ++i) {
      sum += std::sin(2.0 * kPi * push_freq_hz_[i] * t + push_phase_[i]);
    }
    const double fade = t < 1.0 ? 0.5 - 0.5 * std::cos(kPi * t) : 1.0;
    return amplitude * fade * (0.5 + 0.5 * sum / static_cast<double>(push_freq_hz_.size()));
  };
  switch (s.kind) {
    case ScenarioKind::kIdle: break;
    case ScenarioKind::kHammer: {
      if (t >= next_hit_s_) {
        std::uniform_real_distribution<double> height(0.6, 1.4), spacing(0.7, 1.3),
            chance(0.0, 1.0);
        pulses_.push_back({next_hit_s_, kHammerPulseS, s.force_n * height(rng_)});
        ++hits_;
        const auto listed = [&](const std::vector<int>& hits) {
          return std::find(hits.begin(), hits.end(), hits_) != hits.end();
        };
        // Test hits change the blow after its random height is drawn: the random stream, and so
        // every other hit, stays as without them.
        if (listed(spec_.overloads)) pulses_.back().height_n = 2.0 * spec_.load_cells[0].range;
        const Pulse first = pulses_.back();
        if (chance(rng_) < 0.1) {  // the hammer bounces: a smaller second hit a few ms later
          std::uniform_real_distribution<double> gap(0.003, 0.008), rebound(0.2, 0.4);
          pulses_.push_back({first.start_s + first.width_s + gap(rng_), kHammerPulseS,
                             first.height_n * rebound(rng_)});
        }
        if (listed(spec_.double_hits))
          pulses_.push_back({first.start_s + 0.015, kHammerPulseS, 0.6 * first.height_n});
        next_hit_s_ += s.spacing_s * spacing(rng_);
      }
      for (const Pulse& p : pulses_) {
        // Value at the middle of the sample: the held force then has the pulse's impulse.
        const double tau = t + 0.5 * dt_s_ - p.start_s;
        if (tau >= 0.0 && tau < p.width_s) force_n += p.height_n * std::sin(kPi * tau / p.width_s);
      }
      std::erase_if(pulses_, [&](const Pulse& p) { return t > p.start_s + p.width_s; });
      break;
    }
    case ScenarioKind::kShaker:
      force_n = s.force_n * std::sin(2.0 * kPi * s.frequency_hz * t);
      if (s.push_n > 0.0) push_n = hand_push(s.push_n);
      break;
    case ScenarioKind::kPush: push_n = hand_push(s.force_n); break;
    case ScenarioKind::kOperate:
      // Random forcing from the start (the filter from rest: no switch-on step), one draw a
      // sample.
      force_n = operate_force_.Next(normal_(rng_));
      if (s.push_n > 0.0) push_n = hand_push(s.push_n);
      break;
    case ScenarioKind::kTone: break;  // on the converters' inputs, not on the rig
    case ScenarioKind::kStep: {
      // Pull by hand through a load cell: ramp up over 0.3 s, hold, let go at once.
      const double ramp_s = 0.3;
      const double u = t - kFirstEventS;
      if (u >= 0.0 && u < ramp_s) force_n = s.force_n * u / ramp_s;
      if (u >= ramp_s && u < ramp_s + s.hold_s) force_n = s.force_n;
      break;
    }
  }
}

void RigSimulator::Step(std::array<std::int32_t, wire::kChannelCount>& raw) {
  if (tick_ == next_rebuild_) Rebuild();
  const double t = static_cast<double>(tick_) * dt_s_;
  double force = 0.0, push = 0.0;
  Excitation(t, force, push);

  const auto n = static_cast<Eigen::Index>(moving_.size());
  // Forces held over this sample: excitation on its mass, the push on the last mass, friction.
  // The shaker drives the last mass of the chain; a mass alone takes every force.
  const int excited = scenario_.kind == ScenarioKind::kShaker ? spec_.dofs() - 1 : scenario_.mass;
  for (Eigen::Index j = 0; j < n; ++j) {
    const int mass = moving_[static_cast<std::size_t>(j)];
    double f = 0.0;
    if (mass == excited || n == 1) f += force;
    if (mass == spec_.dofs() - 1 || n == 1) f += push;
    const double v = state_(n + j);
    const double fc = spec_.coulomb_n[static_cast<std::size_t>(mass)];
    f -= fc * std::clamp(v / kStictionSpeedMPerS, -1.0, 1.0);
    input_(j) = f;
  }
  output_.noalias() = discrete_.C * state_;
  output_.noalias() += discrete_.D * input_;
  part_outputs_[0] = output_;
  for (std::size_t p = 0; p < part_steps_.size(); ++p) {
    // Only the instants a response input reads (not load cell 2's).
    if (std::none_of(channel_outputs_.begin() + 2, channel_outputs_.end(),
                     [&](std::size_t o) { return o == 1 + p; }))
      continue;
    const model::StateSpace& step = part_steps_[p].second;
    part_state_.noalias() = step.A * state_;
    part_state_.noalias() += step.B * input_;
    part_outputs_[1 + p].noalias() = step.C * part_state_;
    part_outputs_[1 + p].noalias() += step.D * input_;
  }

  // Each response input reads its mass at its own instant (0 when its mass does not move); the
  // truths are each mass's position at the encoders' instant, acceleration at the
  // accelerometers'.
  const auto read = [&](std::size_t channel, Eigen::Index row) {
    return row < 0 ? 0.0 : part_outputs_[channel_outputs_[channel]](row);
  };
  std::array<double, 4> response{};
  for (std::size_t c = 0; c < response.size(); ++c) response[c] = read(2 + c, input_row_[c]);
  std::array<double, kMaxMasses> x{}, a{};
  for (std::size_t mass = 0; mass < x.size(); ++mass) {
    x[mass] = read(4, x_row_[mass]);
    a[mass] = read(2, a_row_[mass]);
  }
  last_ = Truths{force, push, x, a};

  std::array<double, 4> analog{force, push, response[0], response[1]};
  const std::array<const AnalogSensor*, 4> sensor{&spec_.load_cells[0], &spec_.load_cells[1],
                                                  &spec_.accelerometers[0],
                                                  &spec_.accelerometers[1]};
  if (scenario_.kind == ScenarioKind::kTone) {
    // A signal generator on the four converter inputs: each converts it at its own instant.
    for (std::size_t c = 0; c < analog.size(); ++c) {
      analog[c] = scenario_.amplitude * sensor[c]->range *
                  std::sin(2.0 * kPi * scenario_.frequency_hz * (t + instant_s_[c]));
    }
  }
  for (std::size_t c = 0; c < analog.size(); ++c)
    raw[c] = sensor[c]->Code(analog[c] + Noise(sensor[c]->noise_rms));
  for (std::size_t i = 0; i < 2; ++i) {
    raw[4 + i] =
        static_cast<std::int32_t>(std::floor(response[2 + i] * spec_.encoder_counts_per_m));
  }

  state_ = discrete_.A * state_ + discrete_.B * input_;
  ++tick_;
}

}  // namespace vibid::emu
