#include "vibid/ident/testing/hammer_test.hpp"

#include <cmath>
#include <random>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::ident {

void HammerTestSpec::Validate(int dofs) const {
  Require(hammer_dof >= 0 && hammer_dof < dofs, "hammer test: hammer DOF out of range");
  for (int d : response_dofs) Require(d >= 0 && d < dofs, "hammer test: response DOF out of range");
  Require(oversample >= 1, "hammer test: oversampling factor must be >= 1");
  Require(fs_hz > 0.0 && hits >= 1 && hit_peak_n > 0.0,
          "hammer test: sample rate, hits and peak must be > 0");
  Require(hit_peak_spread >= 0.0 && hit_peak_spread < 1.0,
          "hammer test: peak spread must be in [0, 1)");
  Require(pulse_width_s > 0.0 && spacing_min_s > pulse_width_s && spacing_max_s >= spacing_min_s &&
              lead_s >= 0.0,
          "hammer test: need pulse width < spacing_min <= spacing_max");
  Require(
      rebound_delay_s >= 0.0 && rebound_fraction >= 0.0 && rebound_fraction < 1.0 &&
          (rebound_fraction == 0.0 ||
           (rebound_delay_s > pulse_width_s && rebound_delay_s < spacing_min_s)),
      "hammer test: a rebound needs pulse width < delay < spacing_min and a fraction in [0, 1)");
  Require(force_noise >= 0.0 && response_noise >= 0.0, "hammer test: noise levels must be >= 0");
}

HammerTestSpec ModalTestSpec(double fs_hz, std::uint64_t seed) {
  return HammerTestSpec{.hammer_dof = 1,
                        .fs_hz = fs_hz,
                        .hits = 10,
                        .pulse_width_s = 0.004,
                        .spacing_min_s = 16,
                        .spacing_max_s = 20,
                        .seed = seed};
}

HammerTestSpec MassTestSpec(double fs_hz, std::uint64_t seed) {
  return HammerTestSpec{.fs_hz = fs_hz,
                        .pulse_width_s = 0.004,
                        .spacing_min_s = 10,
                        .spacing_max_s = 13,
                        .seed = seed};
}

HammerTestRecord SimulateHammerTest(const model::Model& rig, const HammerTestSpec& spec) {
  spec.Validate(rig.dofs());
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  model::ForceInput input;
  HammerTestRecord rec;
  double t = spec.lead_s;
  for (int h = 0; h < spec.hits; ++h) {
    model::ForceShape s;
    s.kind = model::ShapeKind::kHalfSine;
    s.dof = spec.hammer_dof;
    s.amp_n = spec.hit_peak_n * (1.0 + spec.hit_peak_spread * (2.0 * unit(rng) - 1.0));
    // Hits start on a sample so the sampled pulse is the same shape every time.
    s.t0_s = std::round(t * spec.fs_hz) / spec.fs_hz;
    s.width_s = spec.pulse_width_s;
    for (const HammerTestSpec::HitChange& c : spec.changes) {
      if (c.hit != h) continue;
      s.amp_n *= c.scale;
      if (c.second_fraction > 0.0) {
        model::ForceShape second = s;
        second.amp_n = s.amp_n * c.second_fraction;
        second.t0_s = s.t0_s + std::round(c.second_delay_s * spec.fs_hz) / spec.fs_hz;
        input.shapes.push_back(second);
      }
    }
    input.shapes.push_back(s);
    if (spec.rebound_fraction > 0.0) {
      model::ForceShape b = s;
      b.amp_n = s.amp_n * spec.rebound_fraction;
      b.t0_s = s.t0_s + std::round(spec.rebound_delay_s * spec.fs_hz) / spec.fs_hz;
      input.shapes.push_back(b);
    }
    rec.hit_times_s.push_back(s.t0_s);
    t += spec.spacing_min_s + (spec.spacing_max_s - spec.spacing_min_s) * unit(rng);
  }
  model::SimulationOptions opt;
  opt.method = spec.friction.empty() ? model::Method::kExact : model::Method::kRk4;
  opt.friction = spec.friction;
  const auto r = static_cast<Eigen::Index>(spec.oversample);
  opt.dt_s = 1.0 / (spec.fs_hz * static_cast<double>(r));
  opt.t_end_s = spec.tail_s > 0.0 ? rec.hit_times_s.back() + spec.tail_s : t;
  const model::SimulationResult sim = model::Simulate(rig, input, opt);
  const Eigen::Index samples = sim.t_s.size() / r;
  // Boxcar average of `r` fine samples per output sample, the same on every channel.
  const auto decimate = [&](const Eigen::VectorXd& fine) {
    Eigen::VectorXd out(samples);
    for (Eigen::Index k = 0; k < samples; ++k) out[k] = fine.segment(k * r, r).mean();
    return out;
  };
  rec.t_s = Eigen::VectorXd::LinSpaced(samples, 0.0, static_cast<double>(samples - 1) / spec.fs_hz);
  rec.force_n = decimate(sim.force_n.col(spec.hammer_dof));
  std::vector<int> dofs = spec.response_dofs;
  if (dofs.empty()) {
    for (int d = 0; d < rig.dofs(); ++d) dofs.push_back(d);
  }
  rec.response.resize(samples, static_cast<Eigen::Index>(dofs.size()));
  for (std::size_t j = 0; j < dofs.size(); ++j) {
    const auto& src = spec.sensor == Quantity::kAcceleration ? sim.a_m_s2
                      : spec.sensor == Quantity::kVelocity   ? sim.v_m_s
                                                             : sim.x_m;
    rec.response.col(static_cast<Eigen::Index>(j)) = decimate(src.col(dofs[j]));
  }
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double fsd = spec.force_noise * rec.force_n.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < rec.force_n.size(); ++i) rec.force_n[i] += fsd * gauss(rng);
  for (Eigen::Index j = 0; j < rec.response.cols(); ++j) {
    const double rsd = spec.response_noise * rec.response.col(j).cwiseAbs().maxCoeff();
    for (Eigen::Index i = 0; i < rec.response.rows(); ++i) rec.response(i, j) += rsd * gauss(rng);
  }
  return rec;
}

std::string FormatHammerTestCsv(const HammerTestRecord& record,
                                const std::vector<std::string>& names,
                                const std::string& force_name) {
  Require(static_cast<Eigen::Index>(names.size()) == record.response.cols(),
          "hammer test: one name per response");
  std::vector<std::string> header{"t_s", force_name};
  std::vector<Eigen::VectorXd> cols{record.t_s, record.force_n};
  for (std::size_t j = 0; j < names.size(); ++j) {
    header.push_back(names[j]);
    cols.push_back(record.response.col(static_cast<Eigen::Index>(j)));
  }
  return FormatCsv(header, cols);
}

}  // namespace vibid::ident
