#include "vibid/dob/design.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "vibid/common/enum_names.hpp"
#include "vibid/common/error.hpp"

namespace vibid::dob {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// As the CLI's --sensor and the design file's "sensor" spell them.
constexpr EnumNames<SensorKind, 3> kSensorNames{{{SensorKind::kDisplacement, "disp"},
                                                 {SensorKind::kVelocity, "vel"},
                                                 {SensorKind::kAcceleration, "acc"}}};

int Degree(const Eigen::VectorXd& p) {
  return static_cast<int>(numerics::TrimLeadingZeros(p).size()) - 1;
}

double Lead(const Eigen::VectorXd& p) { return numerics::TrimLeadingZeros(p)[0]; }

void Append(std::vector<Complex>& to, const std::vector<Complex>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

std::string FormatComplex(Complex c) {
  std::ostringstream os;
  os.precision(6);
  os << c.real() << (c.imag() < 0 ? " - " : " + ") << std::abs(c.imag()) << "j";
  return os.str();
}

fixed::InputKind InputKindOf(SensorKind s) {
  switch (s) {
    case SensorKind::kDisplacement: return fixed::InputKind::kDisplacement;
    case SensorKind::kVelocity: return fixed::InputKind::kVelocity;
    case SensorKind::kAcceleration: return fixed::InputKind::kAcceleration;
  }
  return fixed::InputKind::kUnused;
}

double DefaultSensorFullScale(SensorKind s) {
  switch (s) {
    case SensorKind::kDisplacement: return 0.05;
    case SensorKind::kVelocity: return 1.0;
    case SensorKind::kAcceleration: return 50.0;
  }
  return 1.0;
}

void ValidateOptions(const DobOptions& o) {
  Require(o.order >= 1, "N must be >= 1, got " + std::to_string(o.order));
  Require(o.relative_degree >= 0 && o.relative_degree <= o.order,
          "r must satisfy 0 <= r <= N (N = " + std::to_string(o.order) +
              "), got r = " + std::to_string(o.relative_degree));
  Require(std::isfinite(o.tau_s) && o.tau_s > 0.0, "tau_s must be > 0");
  Require(
      std::isfinite(o.fs_hz) && o.fs_hz > 0.0 && o.fs_hz == std::floor(o.fs_hz) && o.fs_hz < 4.0e9,
      "fs_hz must be a positive whole number of Hz");
  Require(1.0 / o.tau_s < std::numbers::pi * o.fs_hz,
          "Q's cut-off 1/tau = " + std::to_string(1.0 / o.tau_s) +
              " rad/s must lie below the Nyquist frequency pi*fs = " +
              std::to_string(std::numbers::pi * o.fs_hz) + " rad/s");
  Require(o.input_dof >= 0 && o.output_dof >= 0, "dof indices must be >= 1");
  Require(std::isfinite(o.leak_hz) && o.leak_hz > 0.0, "leak_hz must be > 0");
  Require(std::isfinite(o.force_full_scale_n) && o.force_full_scale_n > 0.0,
          "force full scale must be > 0");
  Require(std::isfinite(o.sensor_full_scale) && o.sensor_full_scale >= 0.0,
          "sensor full scale must be >= 0");
  Require(std::isfinite(o.output_full_scale_n) && o.output_full_scale_n >= 0.0,
          "output full scale must be >= 0");
}

// Q's poles and zeros, from its polynomials.
Zpk QZpk(const QFilter& q) {
  Zpk z;
  z.zeros = numerics::PolynomialRoots(q.num);
  z.poles = numerics::PolynomialRoots(q.den);
  z.gain = Lead(q.num) / Lead(q.den);
  return z;
}

std::vector<Complex> LeakPoles(const DobOptions& o) {
  const int m = static_cast<int>(o.sensor);
  return std::vector<Complex>(static_cast<std::size_t>(m), Complex(-kTwoPi * o.leak_hz, 0.0));
}

std::string RelativeDegreeMessage(int r, int plant, const std::string& what) {
  return "r = " + std::to_string(r) + " is below the relative degree " + std::to_string(plant) +
         " of " + what +
         ": Q G_A^-1 would not be proper (realizable); use r >= " + std::to_string(plant);
}

}  // namespace

const char* SensorName(SensorKind kind) { return NameOf(kSensorNames, kind, "?"); }

SensorKind ParseSensorKind(std::string_view name) {
  return ParseName(kSensorNames, name, "sensor");
}

double QBandEdgeHz(const QFilter& q, double tolerance) {
  const double wc = 1.0 / q.tau_s;
  double lo = wc * 1e-4;
  double hi = wc * 10.0;
  const auto err = [&](double w) {
    const Complex s(0.0, w);
    return std::abs(
        numerics::EvaluatePolynomial(q.num, s) / numerics::EvaluatePolynomial(q.den, s) - 1.0);
  };
  if (err(lo) >= tolerance) return lo / kTwoPi;
  // |Q - 1| grows monotonically over the pass band for these prototypes; bisect on log scale.
  for (int i = 0; i < 200; ++i) {
    const double mid = std::sqrt(lo * hi);
    (err(mid) < tolerance ? lo : hi) = mid;
  }
  return lo / kTwoPi;
}

namespace {

// The observer's sensor paths in continuous time, one input each (kind/dof/full scale set,
// sections filled after discretization), and why the design is refused (empty: it is not).
struct SensorPaths {
  std::vector<Zpk> zpk;
  std::vector<ObserverPath> shells;
  int plant_relative_degree = 0;
  std::string refusal;
};

// G_A's zeros become poles of the observer: they must lie strictly in the left half plane.
std::string ZeroRefusal(const std::vector<Complex>& g_zeros) {
  for (const Complex& z : g_zeros) {
    if (z.real() >= -1e-9 * std::max(1.0, std::abs(z))) {
      return "G_A has a zero at s = " + FormatComplex(z) + " rad/s (" +
             std::to_string(std::abs(z) / kTwoPi) +
             " Hz) on or right of the imaginary axis, so G_A^-1 is " + "unstable" +
             (std::abs(z.real()) < 1e-9 * std::max(1.0, std::abs(z))
                  ? ": the nominal model is undamped there; give it the identified damping"
                  : ": the model is non-minimum-phase for this sensor/force pair");
    }
  }
  return {};
}

// SISO form: Q G_A^-1 from the sensor on the output mass.
SensorPaths SisoSensorPath(const NominalPlant& plant, const DobOptions& o, const Zpk& q) {
  Require(plant.receptance_num.size() > 0 && plant.receptance_den.size() > 0,
          "the nominal model gives no transfer function for the SISO form");
  const Eigen::VectorXd& num = plant.receptance_num;
  const Eigen::VectorXd& den = plant.receptance_den;
  Require(numerics::TrimLeadingZeros(num).cwiseAbs().maxCoeff() > 0.0,
          "the nominal transfer function from the force to the sensor is zero: the sensor does not "
          "see the force");
  const int m = static_cast<int>(o.sensor);
  SensorPaths out;
  out.plant_relative_degree = Degree(den) - Degree(num) - m;
  const std::string what = "G_A (force on m" + std::to_string(o.input_dof + 1) + " to " +
                           SensorName(o.sensor) + " of m" + std::to_string(o.output_dof + 1) + ")";
  Require(o.relative_degree >= out.plant_relative_degree,
          RelativeDegreeMessage(o.relative_degree, out.plant_relative_degree, what));
  const auto g_zeros = numerics::PolynomialRoots(num);
  const auto g_poles = numerics::PolynomialRoots(den);
  out.refusal = ZeroRefusal(g_zeros);
  Zpk sensor = q;
  Append(sensor.zeros, g_poles);
  Append(sensor.poles, g_zeros);
  Append(sensor.poles, LeakPoles(o));
  sensor.gain = q.gain * Lead(den) / Lead(num);
  out.zpk.push_back(sensor);
  out.shells.push_back(ObserverPath{.kind = InputKindOf(o.sensor),
                                    .dof = o.output_dof,
                                    .full_scale = o.sensor_full_scale,
                                    .sos = {}});
  return out;
}

// MIMO form: the input mass's row of M s^2 + C s + K, one sensor path per mass it couples to.
SensorPaths MimoSensorPaths(const NominalPlant& plant, const DobOptions& o, const Zpk& q) {
  const Eigen::Index n = plant.m_row.size();
  Require(n > 0 && plant.c_row.size() == n && plant.k_row.size() == n,
          "the nominal model gives no M, C, K row for the MIMO form");
  Require(o.input_dof < n, "input dof " + std::to_string(o.input_dof + 1) +
                               " exceeds the model's " + std::to_string(n) + " masses");
  const int m = static_cast<int>(o.sensor);
  SensorPaths out;
  int plant_degree = -100;
  for (Eigen::Index l = 0; l < n; ++l) {
    const Eigen::Vector3d row(plant.m_row[l], plant.c_row[l], plant.k_row[l]);
    if (row.cwiseAbs().maxCoeff() == 0.0) continue;
    const Eigen::VectorXd poly = numerics::TrimLeadingZeros(row, 0.0);
    plant_degree = std::max(plant_degree, static_cast<int>(poly.size()) - 1 - m);
    Zpk sensor = q;
    Append(sensor.zeros, numerics::PolynomialRoots(poly));
    Append(sensor.poles, LeakPoles(o));
    sensor.gain = q.gain * poly[0];
    out.zpk.push_back(sensor);
    out.shells.push_back(ObserverPath{.kind = InputKindOf(o.sensor),
                                      .dof = static_cast<int>(l),
                                      .full_scale = o.sensor_full_scale,
                                      .sos = {}});
  }
  Require(!out.zpk.empty(), "the model's row for m" + std::to_string(o.input_dof + 1) + " is zero");
  Require(out.zpk.size() + 1 <= fixed::kMaxInputs,
          "the MIMO form needs " + std::to_string(out.zpk.size() + 1) +
              " inputs; the fixed-point observer takes at most " +
              std::to_string(fixed::kMaxInputs));
  out.plant_relative_degree = plant_degree;
  Require(o.relative_degree >= plant_degree,
          RelativeDegreeMessage(o.relative_degree, plant_degree,
                                "the row operator of m" + std::to_string(o.input_dof + 1) + " (" +
                                    SensorName(o.sensor) + " sensors)"));
  return out;
}

// Discretizes every continuous path into the sections of its input; records the largest pole
// radius.
void DiscretizePaths(const DobOptions& o, std::vector<ObserverPath>& shells, DobDesign& design) {
  const double warp = 1.0 / o.tau_s;
  for (std::size_t i = 0; i < design.continuous.size(); ++i) {
    const Zpk digital = o.discretization == Discretization::kTustin
                            ? TustinZpk(design.continuous[i], o.fs_hz, warp)
                            : ZeroOrderHoldZpk(design.continuous[i], o.fs_hz);
    shells[i].sos = ZpkToSos(digital);
    Require(shells[i].sos.size() <= fixed::kMaxSections,
            "the observer path for input " + std::to_string(i + 1) + " needs " +
                std::to_string(shells[i].sos.size()) + " second-order sections; at most " +
                std::to_string(fixed::kMaxSections) + " fit (lower N or simplify the model)");
    for (const Complex& p : digital.poles)
      design.max_pole_radius = std::max(design.max_pole_radius, std::abs(p));
  }
  design.paths = shells;
}

}  // namespace

DobDesign DesignObserver(const NominalPlant& plant, const DobOptions& options) {
  ValidateOptions(options);
  DobDesign design;
  design.options = options;
  DobOptions& o = design.options;
  if (o.sensor_full_scale == 0.0) o.sensor_full_scale = DefaultSensorFullScale(o.sensor);
  if (o.output_full_scale_n == 0.0) o.output_full_scale_n = 2.0 * o.force_full_scale_n;
  design.q = MakeQFilter(o.order, o.relative_degree, o.tau_s, o.prototype);
  const Zpk q = QZpk(design.q);
  const int m = static_cast<int>(o.sensor);

  SensorPaths sensors =
      o.form == ObserverForm::kSiso ? SisoSensorPath(plant, o, q) : MimoSensorPaths(plant, o, q);
  design.plant_relative_degree = sensors.plant_relative_degree;
  Zpk force_path = q;
  force_path.gain = -q.gain;
  design.continuous = sensors.zpk;
  design.continuous.push_back(force_path);
  sensors.shells.push_back(ObserverPath{.kind = fixed::InputKind::kForce,
                                        .dof = o.input_dof,
                                        .full_scale = o.force_full_scale_n,
                                        .sos = {}});
  DiscretizePaths(o, sensors.shells, design);

  std::string refusal = sensors.refusal;
  if (refusal.empty() && design.max_pole_radius >= 1.0 - 1e-12) {
    refusal = "the discrete filter has a pole at |z| = " + std::to_string(design.max_pole_radius) +
              " (on or outside the unit circle)";
  }
  design.stable = refusal.empty();
  design.message = refusal;
  design.valid_band_lo_hz = m == 0 ? 0.0 : 10.0 * o.leak_hz;
  design.valid_band_hi_hz = std::min(QBandEdgeHz(design.q, 0.1), o.fs_hz / 2.0);
  if (design.stable) {
    design.fixed = QuantizeObserver(
        design.paths, QuantizeOptions{.sample_rate_hz = static_cast<std::uint32_t>(o.fs_hz),
                                      .output_dof = o.input_dof,
                                      .output_full_scale_n = o.output_full_scale_n});
    if (!design.fixed.ok) {
      design.stable = false;
      design.message = design.fixed.message;
    }
  }
  return design;
}

}  // namespace vibid::dob
