#include "vibid/ident/spectral.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <span>
#include <thread>
#include <vector>

#include <kissfft.hh>

#include "vibid/common/error.hpp"

namespace vibid::ident {

Window ParseWindow(std::string_view name) {
  if (name == "rect" || name == "rectangular" || name == "boxcar") return Window::kRectangular;
  if (name == "hann" || name == "hanning") return Window::kHann;
  if (name == "hamming") return Window::kHamming;
  if (name == "blackmanharris") return Window::kBlackmanHarris;
  if (name == "flattop") return Window::kFlatTop;
  throw InputError("unknown window '" + std::string(name) +
                   "' (known: rect, hann, hamming, blackmanharris, flattop)");
}

const char* WindowName(Window window) {
  switch (window) {
    case Window::kRectangular: return "rect";
    case Window::kHann: return "hann";
    case Window::kHamming: return "hamming";
    case Window::kBlackmanHarris: return "blackmanharris";
    case Window::kFlatTop: return "flattop";
  }
  return "unknown";
}

Eigen::VectorXd MakeWindow(Window window, std::size_t n) {
  Eigen::VectorXd w(static_cast<Eigen::Index>(n));
  // Cosine-sum coefficients as scipy.signal.windows defines them (alternating signs applied below).
  std::vector<double> a;
  switch (window) {
    case Window::kRectangular: a = {1.0}; break;
    case Window::kHann: a = {0.5, 0.5}; break;
    case Window::kHamming: a = {0.54, 0.46}; break;
    case Window::kBlackmanHarris: a = {0.35875, 0.48829, 0.14128, 0.01168}; break;
    case Window::kFlatTop:
      a = {0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368};
      break;
  }
  const double dn = static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = 2.0 * std::numbers::pi * static_cast<double>(i) / dn;
    double v = 0.0;
    double sign = 1.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      v += sign * a[k] * std::cos(static_cast<double>(k) * x);
      sign = -sign;
    }
    w[static_cast<Eigen::Index>(i)] = v;
  }
  return w;
}

Estimator ParseEstimator(std::string_view name) {
  if (name == "h1" || name == "H1") return Estimator::kH1;
  if (name == "h2" || name == "H2") return Estimator::kH2;
  if (name == "hv" || name == "Hv") return Estimator::kHv;
  throw InputError("unknown estimator '" + std::string(name) + "' (known: h1, h2, hv)");
}

const char* EstimatorName(Estimator estimator) {
  switch (estimator) {
    case Estimator::kH1: return "h1";
    case Estimator::kH2: return "h2";
    case Estimator::kHv: return "hv";
  }
  return "unknown";
}

Quantity ParseQuantity(std::string_view name) {
  if (name == "disp" || name == "displacement" || name == "receptance")
    return Quantity::kDisplacement;
  if (name == "vel" || name == "velocity" || name == "mobility") return Quantity::kVelocity;
  if (name == "acc" || name == "acceleration" || name == "accelerance")
    return Quantity::kAcceleration;
  throw InputError("unknown sensor/FRF type '" + std::string(name) +
                   "' (known: disp|receptance, vel|mobility, acc|accelerance)");
}

const char* FrfKindName(Quantity quantity) {
  switch (quantity) {
    case Quantity::kDisplacement: return "receptance";
    case Quantity::kVelocity: return "mobility";
    case Quantity::kAcceleration: return "accelerance";
  }
  return "unknown";
}

void WelchOptions::Validate(std::size_t record_samples) const {
  Require(segment_samples >= 4, "segment length must be at least 4 samples");
  Require(overlap_samples < segment_samples, "overlap (" + std::to_string(overlap_samples) +
                                                 " samples) must be smaller than the segment (" +
                                                 std::to_string(segment_samples) + " samples)");
  Require(record_samples >= segment_samples, "record has " + std::to_string(record_samples) +
                                                 " samples, fewer than one segment of " +
                                                 std::to_string(segment_samples));
}

struct RealFft::Plan {
  // Even n: kissfft's packed real transform of n/2 complex points; odd n: a full complex one.
  kissfft<double> fft;
  std::vector<std::complex<double>> in;
  std::vector<std::complex<double>> out;
  Plan(std::size_t n, bool even)
      : fft(even ? n / 2 : n, false), in(even ? 0 : n), out(even ? n / 2 : n) {}
};

RealFft::RealFft(std::size_t n) : n_(n), plan_(std::make_unique<Plan>(n, n % 2 == 0)) {
  Require(n >= 2, "FFT length must be at least 2");
}

RealFft::~RealFft() = default;

void RealFft::Transform(const double* in, Eigen::VectorXcd& out) {
  const std::size_t half = n_ / 2;
  out.resize(static_cast<Eigen::Index>(half + 1));
  if (n_ % 2 == 0) {
    plan_->fft.transform_real(in, plan_->out.data());
    out[0] = std::complex<double>(plan_->out[0].real(), 0.0);
    out[static_cast<Eigen::Index>(half)] = std::complex<double>(plan_->out[0].imag(), 0.0);
    for (std::size_t k = 1; k < half; ++k) out[static_cast<Eigen::Index>(k)] = plan_->out[k];
  } else {
    for (std::size_t i = 0; i < n_; ++i) plan_->in[i] = std::complex<double>(in[i], 0.0);
    plan_->fft.transform(plan_->in.data(), plan_->out.data());
    for (std::size_t k = 0; k <= half; ++k) out[static_cast<Eigen::Index>(k)] = plan_->out[k];
  }
}

namespace {

// Segments are summed in kPartials contiguous runs, each in segment order, and the runs are added
// in run order. The runs do not depend on the thread count, so neither does any bit of the result.
constexpr std::size_t kPartials = 8;

// Running sums of one run of segments (unscaled |F|^2, |X_j|^2, F^* X_j).
struct PartialSums {
  Eigen::VectorXd gff;
  Eigen::MatrixXd gxx;
  Eigen::MatrixXcd gfx;
};

// One thread's plan and buffers, allocated once, reused for every segment it transforms.
class SegmentWorker {
 public:
  SegmentWorker(const Eigen::VectorXd& window, Detrend detrend)
      : window_(window),
        detrend_(detrend),
        fft_(static_cast<std::size_t>(window.size())),
        buf_(window.size()) {}

  void Sum(const double* force, std::span<const double* const> responses, std::size_t first_seg,
           std::size_t end_seg, std::size_t hop, PartialSums& out) {
    const Eigen::Index lines = out.gff.size();
    double* const gff = out.gff.data();
    for (std::size_t s = first_seg; s < end_seg; ++s) {
      const std::size_t start = s * hop;
      Transform(force + start, fspec_);
      const std::complex<double>* const f = fspec_.data();
      for (Eigen::Index i = 0; i < lines; ++i)
        gff[i] += f[i].real() * f[i].real() + f[i].imag() * f[i].imag();
      for (std::size_t jj = 0; jj < responses.size(); ++jj) {
        const auto j = static_cast<Eigen::Index>(jj);
        Transform(responses[jj] + start, xspec_);
        const std::complex<double>* const x = xspec_.data();
        double* const gxx = out.gxx.col(j).data();
        std::complex<double>* const gfx = out.gfx.col(j).data();
        // Written out rather than f^* x with std::complex: no call into the C99 NaN-recovery
        // multiply.
        for (Eigen::Index i = 0; i < lines; ++i) {
          const double fr = f[i].real(), fi = f[i].imag(), xr = x[i].real(), xi = x[i].imag();
          gxx[i] += xr * xr + xi * xi;
          gfx[i] += std::complex<double>(fr * xr + fi * xi, fr * xi - fi * xr);
        }
      }
    }
  }

 private:
  void Transform(const double* x, Eigen::VectorXcd& spectrum) {
    const Eigen::Index n = window_.size();
    const Eigen::Map<const Eigen::VectorXd> seg(x, n);
    const double mean = detrend_ == Detrend::kConstant ? seg.mean() : 0.0;
    buf_.array() = (seg.array() - mean) * window_.array();
    fft_.Transform(buf_.data(), spectrum);
  }

  const Eigen::VectorXd& window_;
  Detrend detrend_;
  RealFft fft_;
  Eigen::VectorXd buf_;
  Eigen::VectorXcd fspec_;
  Eigen::VectorXcd xspec_;
};

std::size_t ThreadsToUse(std::size_t requested, std::size_t runs) {
  const std::size_t wanted =
      requested ? requested : std::max(1u, std::thread::hardware_concurrency());
  return std::min(wanted, runs);
}

}  // namespace

namespace {

CrossSpectra Welch(const Eigen::Ref<const Eigen::VectorXd>& force,
                   std::span<const double* const> responses, double fs_hz,
                   const WelchOptions& options) {
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  Require(!responses.empty(), "at least one response channel is needed");
  const auto total = static_cast<std::size_t>(force.size());
  options.Validate(total);
  const std::size_t seg = options.segment_samples;
  const std::size_t hop = seg - options.overlap_samples;
  const std::size_t nseg = (total - seg) / hop + 1;
  const Eigen::VectorXd window = MakeWindow(options.window, seg);
  const auto lines = static_cast<Eigen::Index>(seg / 2 + 1);
  const auto nresp = static_cast<Eigen::Index>(responses.size());

  const std::size_t nparts = std::min(kPartials, nseg);
  std::vector<PartialSums> parts(nparts);
  for (PartialSums& p : parts) {
    p.gff = Eigen::VectorXd::Zero(lines);
    p.gxx = Eigen::MatrixXd::Zero(lines, nresp);
    p.gfx = Eigen::MatrixXcd::Zero(lines, nresp);
  }
  // Thread t sums runs t, t + T, t + 2T, ...; run k covers segments [k nseg / P, (k + 1) nseg / P).
  const std::size_t nthreads = ThreadsToUse(options.threads, nparts);
  const auto work = [&](std::size_t t) {
    SegmentWorker worker(window, options.detrend);
    for (std::size_t k = t; k < nparts; k += nthreads) {
      worker.Sum(force.data(), responses, k * nseg / nparts, (k + 1) * nseg / nparts, hop,
                 parts[k]);
    }
  };
  {
    std::vector<std::jthread> threads;
    for (std::size_t t = 1; t < nthreads; ++t) threads.emplace_back(work, t);
    work(0);
  }

  CrossSpectra out;
  out.freq_hz = Eigen::VectorXd::LinSpaced(
      lines, 0.0, static_cast<double>(lines - 1) * fs_hz / static_cast<double>(seg));
  out.gff = std::move(parts[0].gff);
  out.gxx = std::move(parts[0].gxx);
  out.gfx = std::move(parts[0].gfx);
  for (std::size_t k = 1; k < nparts; ++k) {
    out.gff += parts[k].gff;
    out.gxx += parts[k].gxx;
    out.gfx += parts[k].gfx;
  }
  out.averages = nseg;
  // Density scaling, one-sided: lines other than DC and Nyquist carry both halves of the spectrum.
  const double scale = 1.0 / (fs_hz * window.squaredNorm() * static_cast<double>(nseg));
  Eigen::VectorXd line_scale = Eigen::VectorXd::Constant(lines, 2.0 * scale);
  line_scale[0] = scale;
  if (seg % 2 == 0) line_scale[lines - 1] = scale;
  out.gff.array() *= line_scale.array();
  for (Eigen::Index j = 0; j < nresp; ++j) {
    out.gxx.col(j).array() *= line_scale.array();
    out.gfx.col(j).array() *= line_scale.array().cast<std::complex<double>>();
  }
  return out;
}

}  // namespace

CrossSpectra WelchSpectra(const Eigen::Ref<const Eigen::VectorXd>& force,
                          const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                          const WelchOptions& options) {
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  Require(responses.rows() == force.size(), "force and responses differ in length");
  std::vector<const double*> columns;
  for (Eigen::Index j = 0; j < responses.cols(); ++j) columns.push_back(responses.col(j).data());
  return Welch(force, columns, fs_hz, options);
}

CrossSpectra WelchSpectra(const Eigen::Ref<const Eigen::VectorXd>& force,
                          std::span<const Eigen::VectorXd* const> responses, double fs_hz,
                          const WelchOptions& options) {
  Require(fs_hz > 0.0 && std::isfinite(fs_hz), "sample rate must be > 0");
  std::vector<const double*> columns;
  for (const Eigen::VectorXd* r : responses) {
    Require(r->size() == force.size(), "force and responses differ in length");
    columns.push_back(r->data());
  }
  return Welch(force, columns, fs_hz, options);
}

Frf FrfFromSpectra(const CrossSpectra& spectra, Estimator estimator, Quantity response_quantity) {
  const Eigen::Index lines = spectra.freq_hz.size();
  const Eigen::Index nresp = spectra.gfx.cols();
  Frf frf;
  frf.freq_hz = spectra.freq_hz;
  frf.h = Eigen::MatrixXcd::Zero(lines, nresp);
  frf.coherence = Eigen::MatrixXd::Zero(lines, nresp);
  frf.quantity = response_quantity;
  frf.measured = response_quantity;
  frf.estimator = estimator;
  frf.averages = spectra.averages;
  const double gff_floor = 1e-300;
  for (Eigen::Index j = 0; j < nresp; ++j) {
    for (Eigen::Index i = 0; i < lines; ++i) {
      const double gff = spectra.gff[i];
      const double gxx = spectra.gxx(i, j);
      const std::complex<double> gfx = spectra.gfx(i, j);
      const double cross2 = std::norm(gfx);
      if (gff <= gff_floor || gxx <= gff_floor || cross2 <= 0.0) continue;
      std::complex<double> h;
      switch (estimator) {
        case Estimator::kH1: h = gfx / gff; break;
        case Estimator::kH2: h = gxx / std::conj(gfx); break;
        case Estimator::kHv: {
          const double d = gxx - gff;
          h = (d + std::sqrt(d * d + 4.0 * cross2)) / (2.0 * std::conj(gfx));
          break;
        }
      }
      frf.h(i, j) = h;
      frf.coherence(i, j) = std::min(1.0, cross2 / (gff * gxx));
    }
  }
  return frf;
}

namespace {

int Order(Quantity q) {
  switch (q) {
    case Quantity::kDisplacement: return 0;
    case Quantity::kVelocity: return 1;
    case Quantity::kAcceleration: return 2;
  }
  return 0;
}

}  // namespace

Frf ConvertFrf(const Frf& frf, Quantity target) {
  const int power = Order(target) - Order(frf.quantity);
  if (power == 0) return frf;
  Frf out = frf;
  out.quantity = target;
  Eigen::Index first = 0;
  if (power < 0) {
    while (first < frf.freq_hz.size() && frf.freq_hz[first] <= 0.0) ++first;
  }
  const Eigen::Index lines = frf.freq_hz.size() - first;
  out.freq_hz = frf.freq_hz.tail(lines);
  out.h = frf.h.bottomRows(lines);
  out.coherence = frf.coherence.bottomRows(lines);
  if (frf.level_rel_var.size() == frf.freq_hz.size())
    out.level_rel_var = frf.level_rel_var.tail(lines);
  for (Eigen::Index i = 0; i < lines; ++i) {
    const std::complex<double> jw(0.0, 2.0 * std::numbers::pi * out.freq_hz[i]);
    std::complex<double> factor(1.0, 0.0);
    for (int p = 0; p < std::abs(power); ++p) factor *= jw;
    if (power < 0) factor = 1.0 / factor;
    out.h.row(i) *= factor;
  }
  return out;
}

double CorrectExponentialWindowDamping(double zeta_measured, double omega_rad_s, double tau_s) {
  if (tau_s <= 0.0) return zeta_measured;
  // The window shifts the pole's real part only: sigma_m = sigma + 1/tau, omega_d unchanged.
  const double sigma_m = zeta_measured * omega_rad_s;
  const double omega_d =
      omega_rad_s * std::sqrt(std::max(0.0, 1.0 - zeta_measured * zeta_measured));
  const double sigma = sigma_m - 1.0 / tau_s;
  return sigma / std::hypot(omega_d, sigma);
}

}  // namespace vibid::ident
