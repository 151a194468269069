#include "vibid/workflow/observer_design.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "vibid/common/error.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/dob/model_plant.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::workflow {

namespace {

void RequireOneOf(const std::string& value, std::initializer_list<const char*> allowed,
                  const std::string& option) {
  std::string list;
  for (const char* a : allowed) {
    if (value == a) return;
    list += (list.empty() ? "" : ", ") + std::string(a);
  }
  throw InputError(option + " '" + value + "' is not one of " + list);
}

}  // namespace

dob::DobOptions ObserverOptions(const model::Model& m, const ObserverDesignRequest& a) {
  Require(a.input_dof >= 1 && a.input_dof <= m.dofs(),
          "--input-dof " + std::to_string(a.input_dof) + " is out of range 1.." +
              std::to_string(m.dofs()));
  Require(a.output_dof >= 1 && a.output_dof <= m.dofs(),
          "--output-dof " + std::to_string(a.output_dof) + " is out of range 1.." +
              std::to_string(m.dofs()));
  RequireOneOf(a.sensor, {"disp", "vel", "acc"}, "--sensor");
  RequireOneOf(a.form, {"siso", "mimo"}, "--form");
  RequireOneOf(a.discretize, {"tustin", "zoh"}, "--discretize");
  RequireOneOf(a.prototype, {"butterworth", "binomial"}, "--prototype");
  const auto positive = [](double v, const char* option) {
    Require(std::isfinite(v) && v > 0.0, std::string(option) + " must be a number > 0");
  };
  positive(a.tau_s, "--tau-s");
  positive(a.fs_hz, "--fs-hz");
  {
    // The board's observer steps once per sample: a design beyond its fastest rate cannot run
    // there (and its quantization check grows with the rate: 1e8 Hz took seconds to refuse).
    const double max_hz = kBoardProfile.max_sample_rate_hz();
    std::ostringstream why;
    why << "--fs-hz " << a.fs_hz << ": the board's observer steps once per sample, at most "
        << max_hz << " Hz; give a rate at or below it";
    Require(a.fs_hz <= max_hz, why.str());
  }
  positive(a.leak_hz, "--leak-hz");
  positive(a.force_fs_n, "--force-fs-n");
  Require(std::isfinite(a.sensor_fs) && a.sensor_fs >= 0.0, "--sensor-fs must be a number >= 0");
  Require(std::isfinite(a.output_fs_n) && a.output_fs_n >= 0.0,
          "--output-fs-n must be a number >= 0");
  dob::DobOptions o;
  o.order = a.order;
  o.relative_degree = a.relative_degree;
  o.tau_s = a.tau_s;
  o.fs_hz = a.fs_hz;
  o.prototype =
      a.prototype == "binomial" ? dob::QPrototype::kBinomial : dob::QPrototype::kButterworth;
  o.sensor = dob::ParseSensorKind(a.sensor);
  o.form = a.form == "mimo" ? dob::ObserverForm::kMimo : dob::ObserverForm::kSiso;
  o.discretization =
      a.discretize == "zoh" ? dob::Discretization::kZeroOrderHold : dob::Discretization::kTustin;
  o.input_dof = a.input_dof - 1;
  o.output_dof = a.output_dof - 1;
  o.leak_hz = a.leak_hz;
  o.force_full_scale_n = a.force_fs_n;
  o.sensor_full_scale = a.sensor_fs;
  o.output_full_scale_n = a.output_fs_n;
  return o;
}

dob::DobDesign DesignObserverFor(const model::Model& m, const ObserverDesignRequest& request) {
  const dob::DobOptions o = ObserverOptions(m, request);
  dob::DobDesign design = dob::DesignObserver(dob::PlantFromModel(m, o.input_dof, o.output_dof), o);
  if (!design.stable) throw NumericalError("observer refused: " + design.message);
  return design;
}

std::string DesignSummary(const dob::DobDesign& d) {
  std::ostringstream os;
  os.precision(6);
  os << "Q: N = " << d.options.order << ", r = " << d.options.relative_degree
     << ", cut-off 1/tau = " << 1.0 / d.options.tau_s << " rad/s ("
     << 1.0 / d.options.tau_s / (2.0 * std::numbers::pi) << " Hz)\n";
  os << "plant relative degree " << d.plant_relative_degree << "; " << d.paths.size() << " inputs:";
  for (const auto& p : d.paths)
    os << " " << dob::InputKindName(p.kind) << "@m" << p.dof + 1 << " (" << p.sos.size()
       << " sections)";
  os << "\nstable: max discrete pole radius " << d.max_pole_radius << "\n";
  os << "valid band: " << d.valid_band_lo_hz << " .. " << d.valid_band_hi_hz << " Hz\n";
  os << "fixed point: predicted noise " << d.fixed.predicted_noise_rms_n << " N rms, SNR "
     << d.fixed.predicted_snr_db << " dB (full-scale sine), checksum 0x" << std::hex
     << d.fixed.description.checksum << std::dec << "\n";
  return os.str();
}

}  // namespace vibid::workflow
