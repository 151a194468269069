#include "vibid/dob/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vibid/common/error.hpp"
#include "vibid/shared/fixed/dob_filter.hpp"

namespace vibid::dob {
namespace {

constexpr double kTwo31 = 2147483648.0;
// Headroom kept below full scale at every section output, for the rounding of earlier sections.
constexpr double kScaleMargin = 0.999;

// Impulse-response length until the slowest pole has decayed to 1e-10 of its start (the l1 and
// l2 norms are then within about 1e-9 relative).
Eigen::Index ImpulseLength(const std::vector<SosSection>& sos) {
  const double r = MaxPoleRadius(sos);
  if (r <= 0.0) return 64;
  const double n = std::log(1e-10) / std::log(std::min(r, 1.0 - 1e-9));
  return static_cast<Eigen::Index>(std::clamp(n + 64.0, 64.0, 4.0e6));
}

Eigen::VectorXd Impulse(Eigen::Index n) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  x[0] = 1.0;
  return x;
}

std::int32_t RoundToInt32(double v) {
  const double r = std::nearbyint(v);
  Require(r >= -kTwo31 && r < kTwo31, "coefficient out of the Q31 range after scaling");
  return static_cast<std::int32_t>(r);
}

// Smallest shift s with every |coefficient| < 2^s and the absolute sum < 2^(1+s) (accumulator).
int SectionShift(const SosSection& s) {
  const double coeffs[5] = {s.b0, s.b1, s.b2, s.a1, s.a2};
  double max_abs = 0.0;
  double sum = 0.0;
  for (const double c : coeffs) {
    max_abs = std::max(max_abs, std::abs(c));
    sum += std::abs(c);
  }
  int shift = 0;
  // Keep one LSB of room below each bound so rounding cannot reach it.
  while (
      shift <= fixed::kMaxSectionShift &&
      (max_abs * std::ldexp(1.0, 31 - shift) >= kTwo31 - 1.0 ||
       sum * std::ldexp(1.0, 31 - shift) >= static_cast<double>(fixed::kMaxCoefficientSum) - 8.0)) {
    ++shift;
  }
  return shift;
}

// Largest factor the numerator of `s` can be multiplied by within the Q31 words and the
// accumulator bound. The shift is the denominator's smallest (the poles keep their resolution)
// unless one more at least doubles the numerator's resolution: a denominator that nearly fills
// its words would otherwise starve the numerator.
double MaxNumeratorScale(const SosSection& s) {
  const double a_sum = 1.0 + std::abs(s.a1) + std::abs(s.a2);
  const double a_max = std::max(std::abs(s.a1), std::abs(s.a2));
  const double b_sum = std::abs(s.b0) + std::abs(s.b1) + std::abs(s.b2);
  const double b_max = std::max({std::abs(s.b0), std::abs(s.b1), std::abs(s.b2)});
  if (b_sum == 0.0) return 1.0;
  int shift = 0;
  while (a_max >= std::ldexp(1.0, shift) * 0.999 || a_sum >= std::ldexp(1.0, 1 + shift) * 0.999)
    ++shift;
  const auto scale = [&](int sh) {
    return 0.99 * std::min((std::ldexp(1.0, 1 + sh) - a_sum) / b_sum, std::ldexp(1.0, sh) / b_max);
  };
  const double tight = scale(shift);
  const double loose = scale(shift + 1);
  return loose / 2.0 > 2.0 * tight ? loose : tight;
}

}  // namespace

double StoredFullScale(double full_scale) {
  return static_cast<double>(static_cast<float>(full_scale));
}

std::int32_t ToQ31(double value, double full_scale) {
  const double q = std::nearbyint(value / full_scale * kTwo31);
  if (!(q == q)) return 0;
  if (q >= kTwo31) return std::numeric_limits<std::int32_t>::max();
  if (q < -kTwo31) return std::numeric_limits<std::int32_t>::min();
  return static_cast<std::int32_t>(q);
}

namespace {

void RequireValidRequest(const std::vector<ObserverPath>& paths, const QuantizeOptions& options) {
  Require(!paths.empty() && paths.size() <= fixed::kMaxInputs,
          "the fixed-point observer takes 1 to " + std::to_string(fixed::kMaxInputs) +
              " inputs, got " + std::to_string(paths.size()));
  Require(options.sample_rate_hz > 0, "sample rate must be > 0");
  Require(std::isfinite(options.output_full_scale_n) && options.output_full_scale_n > 0.0,
          "output full scale must be > 0 N");
  Require(options.output_dof >= 0 && options.output_dof < 256, "output dof out of range");
}

// The path's sections scaled so that no section output exceeds full scale, with the gain the
// output stage must restore.
struct ScaledPath {
  std::vector<SosSection> sections;
  Eigen::Index impulse_length = 0;
  double l1_gain = 0.0;      // of the whole path, in Q31 units
  double output_gain = 1.0;  // 1 / gain of the scaled cascade
};

// l1 scaling. g_k, the gain from the path input to section k's output, must keep that output
// within full scale for any input: g_k <= margin / l1_k. The last section fills its range; going
// backwards, each earlier section gives up some range where that lets the next section's
// numerator fill its Q31 words (same shift as its denominator needs): numerators with zeros near
// z = 1 are differences of nearly equal coefficients, so their size is their precision.
ScaledPath ScaleByL1(const std::vector<SosSection>& sos, std::size_t path_index) {
  ScaledPath out;
  out.impulse_length = ImpulseLength(sos);
  Eigen::VectorXd h = Impulse(out.impulse_length);
  std::vector<double> l1(sos.size());
  for (std::size_t k = 0; k < sos.size(); ++k) {
    h = FilterSos({sos[k]}, h);
    l1[k] = h.cwiseAbs().sum();
    Require(std::isfinite(l1[k]) && l1[k] > 0.0,
            "path " + std::to_string(path_index) + " has a zero or unbounded section");
  }
  std::vector<double> g(sos.size());
  g.back() = kScaleMargin / l1.back();
  for (std::size_t k = sos.size() - 1; k > 0; --k) {
    // At most 3 bits of range given up, so the earlier section's rounding stays negligible.
    const double full = kScaleMargin / l1[k - 1];
    g[k - 1] = std::clamp(g[k] / MaxNumeratorScale(sos[k]), full / 8.0, full);
  }
  out.sections = sos;
  for (std::size_t k = 0; k < sos.size(); ++k) {
    const double step = g[k] / (k == 0 ? 1.0 : g[k - 1]);
    out.sections[k].b0 *= step;
    out.sections[k].b1 *= step;
    out.sections[k].b2 *= step;
  }
  out.l1_gain = h.cwiseAbs().sum();
  out.output_gain = 1.0 / g.back();
  return out;
}

void QuantizeSections(const std::vector<SosSection>& scaled, std::size_t path_index,
                      fixed::Path& p) {
  p.section_count = static_cast<std::uint8_t>(scaled.size());
  for (std::size_t k = 0; k < scaled.size(); ++k) {
    const SosSection& s = scaled[k];
    const int shift = SectionShift(s);
    Require(shift <= fixed::kMaxSectionShift,
            "path " + std::to_string(path_index) + " section " + std::to_string(k) +
                " has coefficients too large for Q31 with the largest shift");
    const double one = std::ldexp(1.0, 31 - shift);
    fixed::Section& q = p.sections[k];
    // Sections with poles and zeros near z = 1 (the rig's resonances at kHz rates) have
    // coefficient sums of order (omega T)^2, and their DC gains are those sums' ratio. Rounding
    // b1 and a1 so that the sums are rounded once (not three times) keeps the section's DC gain,
    // which slow disturbances see, within half an LSB of each sum.
    q.b0 = RoundToInt32(s.b0 * one);
    q.b2 = RoundToInt32(s.b2 * one);
    q.b1 = RoundToInt32(std::nearbyint((s.b0 + s.b1 + s.b2) * one) - q.b0 - q.b2);
    q.a2 = RoundToInt32(s.a2 * one);
    q.a1 = RoundToInt32(std::nearbyint((1.0 + s.a1 + s.a2) * one) - one - q.a2);
    q.shift = static_cast<std::uint8_t>(shift);
  }
}

void QuantizeOutputGain(double output_gain, std::size_t path_index, fixed::Path& p) {
  int out_shift = 0;
  while (out_shift < fixed::kMaxOutputShift &&
         std::abs(output_gain) >= std::ldexp(1.0, out_shift) * (1.0 - 1e-9)) {
    ++out_shift;
  }
  Require(std::abs(output_gain) < std::ldexp(1.0, out_shift),
          "path " + std::to_string(path_index) + " output gain " + std::to_string(output_gain) +
              " exceeds the format's range; raise the output full scale");
  p.output_shift = static_cast<std::uint8_t>(out_shift);
  p.output_gain = RoundToInt32(output_gain * std::ldexp(1.0, 31 - out_shift));
}

// Rounding noise at d_hat in (Q31 LSB)^2: 1/12 LSB^2 at each section output, through the section's
// own poles (shaped by (1 - z^-1)^2 when the error feedback is on), the rest of the path and the
// output gain; plus the output term's own rounding, added to `noise_var_q31`. Enables the
// feedback where it lowers that noise.
void ChooseErrorFeedback(const ScaledPath& path, fixed::Path& p, double& noise_var_q31) {
  const std::vector<SosSection>& scaled = path.sections;
  for (std::size_t k = 0; k < scaled.size(); ++k) {
    std::vector<SosSection> chain(scaled.begin() + static_cast<std::ptrdiff_t>(k), scaled.end());
    const SosSection own = chain.front();
    chain.front() = SosSection{.b0 = 1.0, .b1 = 0.0, .b2 = 0.0, .a1 = own.a1, .a2 = own.a2};
    const double plain = FilterSos(chain, Impulse(path.impulse_length)).squaredNorm();
    chain.front().b1 = -2.0;
    chain.front().b2 = 1.0;
    const double shaped = FilterSos(chain, Impulse(path.impulse_length)).squaredNorm();
    if (shaped < plain) p.sections[k].feedback = fixed::ErrorFeedback::kSecondOrder;
    noise_var_q31 += std::min(plain, shaped) * path.output_gain * path.output_gain / 12.0;
  }
  noise_var_q31 += 1.0 / 12.0;
}

// Fills input i of the description and adds the path's rounding noise to `noise_var_q31`.
void QuantizePath(const ObserverPath& path, std::size_t i, double out_fs,
                  fixed::FilterDescription& d, QuantizeResult& result, double& noise_var_q31) {
  Require(path.sos.size() <= fixed::kMaxSections,
          "path " + std::to_string(i) + " needs " + std::to_string(path.sos.size()) +
              " second-order sections; the fixed-point format holds at most " +
              std::to_string(fixed::kMaxSections));
  Require(std::isfinite(path.full_scale) && path.full_scale > 0.0, "input full scale must be > 0");
  Require(path.dof >= 0 && path.dof < 256, "input dof out of range");
  const double in_fs = StoredFullScale(path.full_scale);
  d.input_kind[i] = path.kind;
  d.input_dof[i] = static_cast<std::uint8_t>(path.dof);
  d.input_full_scale_bits[i] = fixed::FullScaleBits(static_cast<float>(in_fs));

  // The path in Q31 units: input fraction of in_fs to output fraction of out_fs.
  std::vector<SosSection> sos = path.sos;
  if (sos.empty()) sos.push_back(SosSection{.b0 = 1.0});
  const double unit = in_fs / out_fs;
  sos.front().b0 *= unit;
  sos.front().b1 *= unit;
  sos.front().b2 *= unit;

  const ScaledPath scaled = ScaleByL1(sos, i);
  result.path_l1_gain.push_back(scaled.l1_gain);
  fixed::Path& p = d.paths[i];
  QuantizeSections(scaled.sections, i, p);
  QuantizeOutputGain(scaled.output_gain, i, p);
  ChooseErrorFeedback(scaled, p, noise_var_q31);
}

}  // namespace

QuantizeResult QuantizeObserver(const std::vector<ObserverPath>& paths,
                                const QuantizeOptions& options) {
  RequireValidRequest(paths, options);
  QuantizeResult result;
  fixed::FilterDescription& d = result.description;
  d.input_count = static_cast<std::uint8_t>(paths.size());
  d.output_dof = static_cast<std::uint8_t>(options.output_dof);
  d.sample_rate_hz = options.sample_rate_hz;
  const double out_fs = StoredFullScale(options.output_full_scale_n);
  d.output_full_scale_bits = fixed::FullScaleBits(static_cast<float>(out_fs));

  double noise_var_q31 = 0.0;  // in (Q31 LSB)^2 at d_hat
  for (std::size_t i = 0; i < paths.size(); ++i)
    QuantizePath(paths[i], i, out_fs, d, result, noise_var_q31);
  fixed::Seal(d);
  const Status st = fixed::ValidateDescription(d);
  result.ok = st == Status::kOk;
  if (!result.ok) {
    result.message =
        std::string("the quantized filter fails validation: ") + StatusName(st) +
        (st == Status::kUnstable ? " (a section's integer poles left the unit circle)" : "");
  }
  result.predicted_noise_rms_n = std::sqrt(noise_var_q31) / kTwo31 * out_fs;
  result.predicted_snr_db = 10.0 * std::log10(0.5 * kTwo31 * kTwo31 / noise_var_q31);
  return result;
}

FixedRun RunFixed(const fixed::FilterDescription& description,
                  const std::vector<Eigen::VectorXd>& inputs_si) {
  fixed::DobFilter filter;
  const Status st = filter.Init(description);
  Require(st == Status::kOk,
          std::string("the fixed-point description does not validate: ") + StatusName(st));
  Require(inputs_si.size() == description.input_count,
          "the fixed-point observer takes " + std::to_string(description.input_count) +
              " inputs, got " + std::to_string(inputs_si.size()));
  const Eigen::Index n = inputs_si.front().size();
  for (const auto& x : inputs_si) Require(x.size() == n, "inputs differ in length");
  const auto out_fs =
      static_cast<double>(fixed::FullScaleValue(description.output_full_scale_bits));
  FixedRun run;
  run.d_hat_n.resize(n);
  run.d_hat_q31.resize(static_cast<std::size_t>(n));
  fixed::InputFrame frame{};
  for (Eigen::Index k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < inputs_si.size(); ++i) {
      const auto full_scale =
          static_cast<double>(fixed::FullScaleValue(description.input_full_scale_bits[i]));
      frame[i] = ToQ31(inputs_si[i][k], full_scale);
    }
    const std::int32_t y = filter.Step(frame);
    run.d_hat_q31[static_cast<std::size_t>(k)] = y;
    run.d_hat_n[k] = y / kTwo31 * out_fs;
  }
  run.saturations = filter.saturation_count();
  return run;
}

Eigen::VectorXd RunFloat(const std::vector<ObserverPath>& paths,
                         const std::vector<Eigen::VectorXd>& inputs_si) {
  Require(inputs_si.size() == paths.size(), "the observer takes " + std::to_string(paths.size()) +
                                                " inputs, got " + std::to_string(inputs_si.size()));
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(inputs_si.front().size());
  for (std::size_t i = 0; i < paths.size(); ++i) {
    Require(inputs_si[i].size() == sum.size(), "inputs differ in length");
    sum += FilterSos(paths[i].sos, inputs_si[i]);
  }
  return sum;
}

}  // namespace vibid::dob
