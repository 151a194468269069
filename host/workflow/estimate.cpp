#include "vibid/workflow/estimate.hpp"

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/text_input.hpp"
#include "vibid/ident/frf_io.hpp"
#include "vibid/ident/harmonic_force.hpp"
#include "vibid/ident/held_levels.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/ident/sample_instants.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::workflow {

void EstimationOptions::Validate() const {
  (void)ident::ParseEstimator(estimator);
  if (!sensor.empty()) {
    for (const std::string& q : SplitList(sensor)) (void)ident::ParseQuantity(q);
  }
  (void)ident::ParseQuantity(kind);
  // Welch options are checked whichever path runs: a typo must not pass silently because the
  // record turned out to be a hammer test.
  (void)ident::ParseWindow(window);
  Require(detrend == "none" || detrend == "constant",
          "--detrend must be none or constant, not '" + detrend + "'");
  Require(overlap < 0 || segment == 0 || static_cast<std::size_t>(overlap) < segment,
          "--overlap must be smaller than the segment");
  Require(!(impact && welch), "--impact and --welch exclude each other; give one of them");
  Require(fs_hz >= 0.0 && std::isfinite(fs_hz), "--fs-hz must be a number > 0");
  Require(use_hits.empty() || hits_file.empty(),
          "--use-hits and --hits both choose the hits; give one of them");
  Require((use_hits.empty() && hits_file.empty()) || !welch,
          "--use-hits and --hits choose hits of an impact test; Welch averaging has none (drop "
          "--welch)");
  if (!use_hits.empty()) (void)ParseHitList(use_hits);
  impact_options.Validate();
}

namespace {

int Order(ident::Quantity q) {
  return q == ident::Quantity::kAcceleration ? 2 : q == ident::Quantity::kVelocity ? 1 : 0;
}

const char* QuantityName(ident::Quantity q) {
  return q == ident::Quantity::kAcceleration ? "an acceleration"
         : q == ident::Quantity::kVelocity   ? "a velocity"
                                             : "a displacement";
}

/// The quantity a unit of the column specs measures, if it is one of motion.
std::optional<ident::Quantity> QuantityOfUnit(std::string_view unit) {
  if (unit == "m" || unit == "cm" || unit == "mm" || unit == "um")
    return ident::Quantity::kDisplacement;
  if (unit == "m/s" || unit == "mm/s") return ident::Quantity::kVelocity;
  if (unit == "g" || unit == "m/s2") return ident::Quantity::kAcceleration;
  return std::nullopt;
}

/// The quantity a board column's unit suffix names (acc1_m_s2, x1_m; file-formats.md).
std::optional<ident::Quantity> QuantityOfBoardName(std::string_view name) {
  const auto ends = [&](std::string_view suffix) {
    return name.size() > suffix.size() && name.substr(name.size() - suffix.size()) == suffix;
  };
  if (ends("_m_s2")) return ident::Quantity::kAcceleration;
  if (ends("_m_s")) return ident::Quantity::kVelocity;
  if (ends("_m")) return ident::Quantity::kDisplacement;
  return std::nullopt;
}

}  // namespace

std::vector<ident::Quantity> ResponseQuantities(const std::vector<ColumnSpec>& responses,
                                                const std::string& sensor) {
  const std::vector<std::string> given =
      sensor.empty() ? std::vector<std::string>{} : SplitList(sensor);
  Require(given.size() <= 1 || given.size() == responses.size(),
          "--sensor names " + std::to_string(given.size()) + " quantities for " +
              std::to_string(responses.size()) +
              " responses (give one for all, or one per response in their order)");
  std::vector<ident::Quantity> out;
  for (std::size_t j = 0; j < responses.size(); ++j) {
    const ColumnSpec& spec = responses[j];
    // An explicit unit decides; without one, a board column's suffix does.
    const std::optional<ident::Quantity> from_unit =
        !spec.unit.empty() ? QuantityOfUnit(spec.unit) : QuantityOfBoardName(spec.name);
    std::optional<ident::Quantity> option;
    if (!given.empty()) option = ident::ParseQuantity(given.size() == 1 ? given[0] : given[j]);
    if (from_unit && option && *from_unit != *option) {
      throw InputError("--sensor says response '" + spec.name + "' measures " +
                       QuantityName(*option) + ", but its unit makes it " +
                       QuantityName(*from_unit) +
                       ": drop --sensor (each response then measures what its unit says) or "
                       "give it per response (--sensor acc,disp,...)");
    }
    out.push_back(from_unit ? *from_unit : option ? *option : ident::Quantity::kAcceleration);
  }
  return out;
}

ident::Quantity CommonQuantity(const std::vector<ident::Quantity>& measured) {
  ident::Quantity top = ident::Quantity::kDisplacement;
  for (ident::Quantity q : measured) {
    if (Order(q) > Order(top)) top = q;
  }
  return top;
}

void AlignMeasuredQuantities(ident::Frf& frf, const std::vector<ident::Quantity>& measured) {
  Require(measured.size() == frf.responses(), "one measured quantity per response is needed");
  for (std::size_t j = 0; j < measured.size(); ++j) {
    const int power = Order(frf.quantity) - Order(measured[j]);
    Require(power >= 0, "a response measured a higher derivative than the FRF's quantity");
    if (power == 0) continue;
    const auto col = static_cast<Eigen::Index>(j);
    for (Eigen::Index i = 0; i < frf.h.rows(); ++i) {
      const std::complex<double> jw(0.0, 2.0 * std::numbers::pi * frf.freq_hz[i]);
      frf.h(i, col) *= power == 1 ? jw : jw * jw;
    }
  }
}

std::size_t DefaultSegment(std::size_t samples) {
  std::size_t seg = 4096;
  while (seg > 16 && seg > samples / 4) seg /= 2;
  return seg;
}

namespace {

/// Shifts every response to the force's sampling instant; one line saying what it did.
std::string Compensate(ident::Frf& frf, double force_s, const std::vector<double>& response_s) {
  std::ostringstream text;
  text.precision(6);
  text << "sampling instants compensated (each response moved to " << frf.force_name
       << "'s instant, H x exp(j omega (t_force - t_response))):";
  for (std::size_t j = 0; j < response_s.size(); ++j)
    text << " " << frf.response_names[j] << " " << (response_s[j] - force_s) * 1e6 << " us;";
  ident::CompensateSampleInstants(frf, force_s, response_s);
  std::string s = text.str();
  s.back() = '\n';
  return s;
}

/// Moves every response to the force's sampling instant when the recording states the instants
/// (a board's recording does); says what it did, or nothing for a recording without them.
std::string CompensateInstants(const std::string& path, ident::Frf& frf) {
  const std::optional<ident::SampleInstants> instants = ident::ReadSampleInstants(path);
  if (!instants) return {};
  const auto instant_of = [&](const std::string& column) {
    const std::optional<double> t = instants->Of(column);
    Require(t.has_value(),
            path + ": the header's sample_instants_us does not name column '" + column + "'");
    return *t;
  };
  std::vector<double> response_s;
  for (const std::string& name : frf.response_names) response_s.push_back(instant_of(name));
  return Compensate(frf, instant_of(frf.force_name), response_s);
}

/// The responses as they are held: a recording's own columns, or one matrix (a caller's array,
/// read in place).
struct Responses {
  std::vector<const Eigen::VectorXd*> columns;
  const Eigen::Ref<const Eigen::MatrixXd>* matrix = nullptr;

  std::size_t count() const {
    return matrix != nullptr ? static_cast<std::size_t>(matrix->cols()) : columns.size();
  }
};

/// The estimation proper, on channels in memory; `source` prefixes notes and warnings.
/// `measured`: what each response measures (ResponseQuantities); the FRF comes out in their
/// CommonQuantity, every column aligned to it.
Estimated Estimate(const Eigen::Ref<const Eigen::VectorXd>& force, const Responses& responses,
                   double fs_hz, const EstimationOptions& o, const std::string& source,
                   const std::vector<ident::Quantity>& measured) {
  o.Validate();
  const ident::Estimator est = ident::ParseEstimator(o.estimator);
  const ident::Quantity sensor = CommonQuantity(measured);
  const auto samples = static_cast<std::size_t>(force.size());
  Estimated out;
  bool impact = o.impact;
  if (!o.welch) {
    // A step, a controller's pulse or a held command is no hammer test and seldom a force: per
    // hit its level changes read as hits (a 0 V sample taken for one), and Welch's FRF of it is
    // noise between the step's spectral lines, where modes then show up by the dozen.
    const ident::HeldLevels held = ident::CheckHeldLevels(force);
    if (held.held) {
      throw InputError(
          source + ": the force column is not a hammer test: " + held.description +
          ", as a step, a pulse or a held command (a motor's voltage) does. An FRF from it is "
          "noise wherever its spectrum has no energy, and its level changes are no hits; the "
          "time-domain methods take such an input: vibid tfest, pem or greybox cart (--input "
          "this column, --output the response), or vibid decay for a free decay after a release "
          "(--welch estimates an FRF all the same, for a broadband held random input)");
    }
  }
  if (!o.impact && !o.welch) {
    const ident::ExcitationCheck check = ident::ClassifyExcitation(force, fs_hz);
    impact = check.impact;
    if (!impact) {
      // A sine is no broadband excitation: Welch's FRF holds the rig at the sine's frequency only,
      // and the peak there, where the force itself peaks, is the force's and no mode.
      const ident::HarmonicForce harmonic = ident::CheckHarmonicForce(force, fs_hz);
      if (harmonic.harmonic) {
        throw InputError(
            source + ": the force column is not a hammer test nor a broadband excitation: " +
            check.description + ", and " + harmonic.description +
            ": a harmonic force (a rotating unbalance at the motor's speed, a shaker's tone). Its "
            "FRF holds the rig at that frequency only and the peak there is the force's, not a "
            "mode; a hammer test or a broadband (random, sweep) excitation gives the modes, and "
            "the time-domain methods take such an input: vibid tfest, pem or greybox (--input "
            "this column, --output the response), or vibid decay for the free decay after the "
            "motor stops (--welch estimates an FRF all the same)");
      }
    }
    out.note =
        source + ": " + check.description + ": " +
        (impact ? "processed as an impact test, one record per hit (--welch forces Welch averaging)"
                : "Welch averaging (--impact forces per-hit records)");
  }
  out.impact = impact;
  if (impact) {
    ident::ImpactOptions io = o.impact_options;
    io.reject_bad_hits = !o.keep_bad_hits;
    if (!o.use_hits.empty()) io.use_hits = ParseHitList(o.use_hits);
    if (!o.hits_file.empty()) io.use_hits = ReadAcceptedHits(o.hits_file);
    // Per-hit records are short copies anyway; the impact code reads one matrix.
    Eigen::MatrixXd copy;
    if (responses.matrix == nullptr) {
      copy.resize(force.size(), static_cast<Eigen::Index>(responses.count()));
      for (std::size_t j = 0; j < responses.count(); ++j)
        copy.col(static_cast<Eigen::Index>(j)) = *responses.columns[j];
    }
    ident::ImpactResult r =
        responses.matrix != nullptr
            ? ident::EstimateImpactFrf(force, *responses.matrix, fs_hz, io, est, sensor)
            : ident::EstimateImpactFrf(force, copy, fs_hz, io, est, sensor);
    out.ringdowns = responses.matrix != nullptr
                        ? ident::RingDownsOf(r, force, *responses.matrix, fs_hz, sensor)
                        : ident::RingDownsOf(r, force, copy, fs_hz, sensor);
    out.frf = std::move(r.frf);
    out.hits = std::move(r.hits);
    for (const std::string& w : r.warnings) out.warnings.push_back(source + ": " + w);
    out.record_samples = r.record_samples;
  } else {
    Require(o.use_hits.empty() && o.hits_file.empty(),
            source + ": --use-hits/--hits choose hits, but the force is no train of hits (" +
                out.note + "); --impact processes it per hit");
    ident::WelchOptions wo;
    wo.window = ident::ParseWindow(o.window);
    wo.detrend = o.detrend == "constant" ? ident::Detrend::kConstant : ident::Detrend::kNone;
    wo.segment_samples = o.segment > 0 ? o.segment : DefaultSegment(samples);
    Require(wo.segment_samples <= samples, source + ": " + std::to_string(samples) +
                                               " samples, fewer than one --segment of " +
                                               std::to_string(wo.segment_samples));
    Require(o.overlap < 0 || static_cast<std::size_t>(o.overlap) < wo.segment_samples,
            "--overlap must be smaller than the segment");
    wo.overlap_samples =
        o.overlap >= 0 ? static_cast<std::size_t>(o.overlap) : wo.segment_samples / 2;
    const ident::CrossSpectra s =
        responses.matrix != nullptr
            ? ident::WelchSpectra(force, *responses.matrix, fs_hz, wo)
            : ident::WelchSpectra(force, std::span<const Eigen::VectorXd* const>(responses.columns),
                                  fs_hz, wo);
    out.frf = ident::FrfFromSpectra(s, est, sensor);
    out.record_samples = wo.segment_samples;
  }
  AlignMeasuredQuantities(out.frf, measured);
  return out;
}

}  // namespace

ident::ImpactOptions::ConverterLimits ConverterLimitsOf(const ColumnSpec& spec,
                                                        const ident::RecordingFacts* facts) {
  const auto scaled = [&](double lo, double hi) -> ident::ImpactOptions::ConverterLimits {
    const double a = lo * spec.scale;
    const double b = hi * spec.scale;
    return {std::min(a, b), std::max(a, b)};
  };
  if (facts != nullptr) {
    if (const ident::ChannelFacts* c = facts->Channel(spec.name); c != nullptr && c->rails)
      return scaled(c->rails->first, c->rails->second);
  }
  // A board's column in raw counts names its converter by its name: an analog input
  // (force1_counts, acc2_counts, ...) spans 0 .. 2^adc_bits - 1; an encoder's counts (x1_counts)
  // are a 32-bit counter's, which a rig's travel never reaches.
  constexpr std::string_view kSuffix = "_counts";
  const std::string& name = spec.name;
  if (name.size() <= kSuffix.size() ||
      name.compare(name.size() - kSuffix.size(), kSuffix.size(), kSuffix) != 0)
    return {};
  const std::string stem = name.substr(0, name.size() - kSuffix.size());
  const bool encoder = stem == "x1" || stem == "x2";
  if (!encoder && stem != "force1" && stem != "force2" && stem != "acc1" && stem != "acc2")
    return {};
  if (encoder) return scaled(-std::ldexp(1.0, 31), std::ldexp(1.0, 31) - 1.0);
  return scaled(0.0, std::ldexp(1.0, kBoardProfile.adc_bits) - 1.0);
}

Estimated EstimateFromRecording(const std::string& path, const EstimationOptions& a) {
  Require(!a.force.empty(), "--force is required to estimate an FRF from the recording " + path);
  Require(!a.responses.empty(),
          "--response is required to estimate an FRF from the recording " + path);
  a.Validate();
  const ColumnSpec fspec = ParseColumnSpec(a.force);
  const std::vector<ColumnSpec> rspecs = ParseColumnList(a.responses);
  RecordingOptions ro;
  if (a.fs_hz > 0.0) ro.fs_hz = a.fs_hz;
  // Only the channels asked for must be numbers: a recording may carry other columns (notes).
  ro.channels.push_back(fspec.name);
  for (const ColumnSpec& spec : rspecs) ro.channels.push_back(spec.name);
  const Recording rec = LoadRecording(path, ro);
  // Channels as the estimation reads them: the recording's own column where the spec does not
  // scale it (x * 1 is x), else a scaled copy; no record-length copy of the rest.
  std::deque<Eigen::VectorXd> scaled;
  const auto channel = [&](const ColumnSpec& spec) -> const Eigen::VectorXd& {
    if (spec.scale == 1.0) return rec.table.Column(spec.name);
    return scaled.emplace_back(rec.Signal(spec));
  };
  const Eigen::VectorXd& force = channel(fspec);
  Responses responses;
  std::vector<std::string> names;
  for (const ColumnSpec& spec : rspecs) {
    responses.columns.push_back(&channel(spec));
    names.push_back(spec.name);
  }
  EstimationOptions with_limits = a;
  std::vector<ident::ImpactOptions::ConverterLimits>& limits =
      with_limits.impact_options.converter_limits;
  if (limits.empty()) {
    // The rails from the recording's sidecar: a clip is a sample at the converter's rail. A
    // recording without one leaves the check unavailable, and the estimation says so.
    const std::optional<ident::RecordingFacts> facts = ident::ReadRecordingFacts(path);
    const ident::RecordingFacts* f = facts ? &*facts : nullptr;
    limits.push_back(ConverterLimitsOf(fspec, f));
    for (const ColumnSpec& spec : rspecs) limits.push_back(ConverterLimitsOf(spec, f));
  }
  Estimated out = Estimate(force, responses, rec.fs_hz, with_limits, path,
                           ResponseQuantities(rspecs, a.sensor));
  out.frf.response_names = names;
  out.frf.force_name = fspec.name;
  out.compensation = CompensateInstants(path, out.frf);
  out.frf = ident::ConvertFrf(out.frf, ident::ParseQuantity(a.kind));
  return out;
}

Estimated EstimateFromSignals(const Eigen::Ref<const Eigen::VectorXd>& force,
                              const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                              const std::string& force_name,
                              const std::vector<std::string>& response_names,
                              const EstimationOptions& options,
                              const std::vector<double>& instants_s) {
  Require(std::isfinite(fs_hz) && fs_hz > 0.0, "fs_hz must be a number > 0");
  Require(force.size() > 0, "the force signal is empty");
  Require(responses.cols() > 0, "no response signal given");
  Require(responses.rows() == force.size(),
          "responses have " + std::to_string(responses.rows()) + " samples, the force " +
              std::to_string(force.size()) + "; give signals of the same length");
  Require(response_names.size() == static_cast<std::size_t>(responses.cols()),
          std::to_string(response_names.size()) + " response names for " +
              std::to_string(responses.cols()) + " response signals");
  Require(force.allFinite(), "the force signal holds NaN or infinite samples");
  Require(responses.allFinite(), "a response signal holds NaN or infinite samples");
  Require(instants_s.empty() || instants_s.size() == response_names.size() + 1,
          "instants_s must give one instant per channel, the force first");
  Responses in_place;
  in_place.matrix = &responses;
  std::vector<ColumnSpec> specs;
  for (const std::string& name : response_names) specs.push_back(ColumnSpec{name, 1.0, ""});
  Estimated out = Estimate(force, in_place, fs_hz, options, "signals",
                           ResponseQuantities(specs, options.sensor));
  out.frf.response_names = response_names;
  out.frf.force_name = force_name;
  if (!instants_s.empty()) {
    out.compensation = Compensate(out.frf, instants_s.front(),
                                  std::vector<double>(instants_s.begin() + 1, instants_s.end()));
  }
  out.frf = ident::ConvertFrf(out.frf, ident::ParseQuantity(options.kind));
  return out;
}

Estimated LoadOrEstimate(const std::string& path, const EstimationOptions& a) {
  const ident::Quantity kind = ident::ParseQuantity(a.kind);
  const bool uff = path.size() > 4 && (path.substr(path.size() - 4) == ".uff" ||
                                       path.substr(path.size() - 4) == ".unv");
  Estimated out;
  if (uff) {
    out.frf = ident::ConvertFrf(ident::LoadFrf(path), kind);
    return out;
  }
  // The first bytes tell an FRF file from a recording: a recording is not read whole twice.
  RequireReadableSize(path, kMaxCsvFileBytes);
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  std::string head(256, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(file.gcount()));
  // Said before anything else: an empty file is neither an FRF nor a recording missing its --force.
  Require(head.size() == 256 || head.find_first_not_of(" \t\r\n") != std::string::npos,
          path + ": empty file");
  if (ident::LooksLikeFrfCsv(head)) {
    out.frf = ident::ConvertFrf(ident::LoadFrf(path), kind);
    return out;
  }
  return EstimateFromRecording(path, a);
}

std::vector<std::string> EstimationNotes(const std::string& path, const Estimated& e) {
  std::vector<std::string> notes;
  if (!e.note.empty()) notes.push_back(e.note);
  notes.insert(notes.end(), e.warnings.begin(), e.warnings.end());
  if (!e.compensation.empty())
    notes.push_back(path + ": " + e.compensation.substr(0, e.compensation.size() - 1));
  std::istringstream in(DescribeHits(e.hits));
  for (std::string line; std::getline(in, line);) notes.push_back(path + ": " + line);
  return notes;
}

ident::Frf JoinColumns(const std::vector<ident::Frf>& frfs,
                       const std::vector<std::string>& sources) {
  Require(!frfs.empty(), "no FRF given");
  ident::Frf out = frfs.front();
  for (std::size_t i = 1; i < frfs.size(); ++i) {
    const ident::Frf& f = frfs[i];
    Require(
        f.freq_hz.size() == out.freq_hz.size() && (f.freq_hz - out.freq_hz).cwiseAbs().maxCoeff() <=
                                                      1e-6 * out.freq_hz.cwiseAbs().maxCoeff(),
        sources[i] + ": frequency lines differ from " + sources[0] +
            "'s; estimate both the same way");
    Require(f.quantity == out.quantity,
            sources[i] + ": FRF kind differs from " + sources[0] + "'s");
    const Eigen::Index c = out.h.cols();
    out.h.conservativeResize(Eigen::NoChange, c + f.h.cols());
    out.coherence.conservativeResize(Eigen::NoChange, c + f.h.cols());
    out.h.rightCols(f.h.cols()) = f.h;
    out.coherence.rightCols(f.h.cols()) = f.coherence;
    out.response_names.insert(out.response_names.end(), f.response_names.begin(),
                              f.response_names.end());
    out.exp_window_tau_s = std::max(out.exp_window_tau_s, f.exp_window_tau_s);
    // Where both forces excite the structure.
    if (f.force_band_max_hz > 0.0 && out.force_band_max_hz > 0.0) {
      out.force_band_min_hz = std::max(out.force_band_min_hz, f.force_band_min_hz);
      out.force_band_max_hz = std::min(out.force_band_max_hz, f.force_band_max_hz);
    }
    Require(f.pretrigger_s == out.pretrigger_s, sources[i] + ": pretrigger differs from " +
                                                    sources[0] + "'s; estimate both the same way");
  }
  return out;
}

std::vector<std::size_t> ParseHitList(const std::string& list) {
  std::vector<std::size_t> hits;
  for (const std::string& item : SplitList(list)) {
    std::string_view text = item;
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
    std::size_t k = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), k);
    Require(ec == std::errc() && end == text.data() + text.size() && k >= 1,
            "--use-hits: '" + std::string(text) + "' is no hit number (hits count from 1: 1,2,4)");
    Require(hits.empty() || k > hits.back(),
            "--use-hits: list each hit once, in increasing order (got " + list + ")");
    hits.push_back(k);
  }
  return hits;
}

std::vector<std::size_t> ReadAcceptedHits(const std::string& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const std::string what = path + " (a hit list)";
  Require(j.is_object() && j.contains("hits") && j.at("hits").is_array(),
          what + ": expected an object with a \"hits\" array, as a hammer session saves it");
  RequireKnownKeys(j, {"format", "hits"}, what);
  Require(j.contains("format") && j.at("format") == kHitListFormat,
          what + ": \"format\" must be \"" + std::string(kHitListFormat) + "\"");
  std::vector<std::size_t> accepted;
  std::size_t expected = 1;
  for (const nlohmann::json& h : j.at("hits")) {
    RequireKnownKeys(h, {"index", "t_s", "peak_n", "verdict", "reason", "accepted", "decided_by"},
                     what + ", a hit");
    Require(h.is_object() && h.contains("index") && h.at("index").is_number_unsigned() &&
                h.contains("accepted") && h.at("accepted").is_boolean(),
            what + ": every hit needs \"index\" (from 1) and \"accepted\" (true or false)");
    const auto index = h.at("index").get<std::size_t>();
    Require(index == expected, what + ": hit " + std::to_string(index) + " listed where hit " +
                                   std::to_string(expected) + " belongs (every hit, in order)");
    ++expected;
    if (h.at("accepted").get<bool>()) accepted.push_back(index);
  }
  Require(!accepted.empty(), what + ": no hit is accepted; accept one to estimate an FRF");
  return accepted;
}

std::string DescribeHits(const std::vector<ident::Hit>& hits) {
  std::ostringstream out;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const ident::Hit& h = hits[i];
    char line[256];
    std::snprintf(line, sizeof line, "hit %zu at %.4f s, peak %.4g, %s%s%s\n", i + 1, h.t_s,
                  h.peak_n, h.used ? "used" : "rejected", h.note.empty() ? "" : ": ",
                  h.note.c_str());
    out << line;
  }
  return out.str();
}

}  // namespace vibid::workflow
