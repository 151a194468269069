#include "vibid/ident/harmonic_force.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "vibid/common/error.hpp"
#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

HarmonicForce CheckHarmonicForce(const Eigen::Ref<const Eigen::VectorXd>& force, double fs_hz) {
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  HarmonicForce out;
  const auto n = static_cast<std::size_t>(force.size());
  if (n < 64) return out;
  // Segments of at most 4096 samples and at least 8 of them where the record allows: lines fine
  // enough to hold a sine's power within a few of them (a Hann window spreads it over 3-4).
  std::size_t segment = 64;
  while (segment * 2 <= std::min<std::size_t>(4096, n / 4)) segment *= 2;
  WelchOptions wo;
  wo.segment_samples = segment;
  wo.overlap_samples = segment / 2;
  wo.detrend = Detrend::kConstant;
  wo.threads = 1;
  const Eigen::VectorXd centred = force.array() - force.mean();
  // The spectra need a response; a silent one costs one record of zeros.
  const Eigen::MatrixXd silent = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), 1);
  const CrossSpectra s = WelchSpectra(centred, silent, fs_hz, wo);
  const Eigen::Index lines = s.gff.size();
  if (lines < 8) return out;
  const double total = s.gff.tail(lines - 1).sum();
  if (!(total > 0.0)) return out;
  Eigen::Index top = 1;
  s.gff.tail(lines - 1).maxCoeff(&top);
  top += 1;
  const Eigen::Index lo = std::max<Eigen::Index>(1, top - kHarmonicHalfWidthLines);
  const Eigen::Index hi = std::min<Eigen::Index>(lines - 1, top + kHarmonicHalfWidthLines);
  out.freq_hz = s.freq_hz[top];
  out.share = s.gff.segment(lo, hi - lo + 1).sum() / total;
  out.harmonic = out.share >= kHarmonicShare;
  std::ostringstream d;
  d.precision(4);
  d << 100.0 * out.share << " % of the force's power lies within " << kHarmonicHalfWidthLines
    << " lines of " << out.freq_hz << " Hz";
  out.description = d.str();
  return out;
}

}  // namespace vibid::ident
