// The sensors' calibration in the intervals (methods §16). Closed form: a load cell that reads
// (1 + eps) times the true force gives H / (1 + eps) and every mass, spring and damper times
// (1 + eps), which no internal check sees; a sensors file stating the sensitivities' uncertainty
// adds a calibration part of 1.96 x sqrt(u_force^2 + u_response^2) x |value| to each interval, in
// quadrature with the statistical part, and both parts are reported.
#include "vibid/workflow/sensor_calibration.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/intervals.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/model.hpp"
#include "vibid/workflow/identify_run.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::workflow {
namespace {

std::string Dir() {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / "vibid_sensor_cal";
  std::filesystem::create_directories(d);
  return d.string();
}

// The 2-mass chain's modal test (hammer on mass 2, both masses measured).
struct Chain {
  model::Model truth = model::MakeChain(Eigen::Vector2d(1.8, 1.5), Eigen::Vector2d(3500.0, 2750.0),
                                        Eigen::Vector2d(2.0, 1.5));
  model::Model nominal = model::MakeChain(
      Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0), Eigen::Vector2d(2.0, 1.5));
  std::string recording;
  std::vector<std::string> mass_tests;  ///< Each mass alone on its spring, hit (1-DOF tests).
};

const Chain& TheChain() {
  static const Chain chain = [] {
    Chain c;
    const ident::HammerTestRecord r =
        ident::SimulateHammerTest(c.truth, ident::ModalTestSpec(500.0, 11));
    c.recording = Dir() + "/modal.csv";
    WriteFileAtomic(c.recording,
                    ident::FormatHammerTestCsv(r, {"acc1_m_s2", "acc2_m_s2"}, "force1_n"));
    const double m[] = {1.8, 1.5}, k[] = {3500.0, 2750.0}, d[] = {2.0, 1.5};
    for (int i = 0; i < 2; ++i) {
      const model::Model one =
          model::MakeChain(Eigen::VectorXd::Constant(1, m[i]), Eigen::VectorXd::Constant(1, k[i]),
                           Eigen::VectorXd::Constant(1, d[i]));
      const ident::HammerTestRecord t =
          ident::SimulateHammerTest(one, ident::MassTestSpec(500.0, 20 + static_cast<unsigned>(i)));
      const std::string acc = "acc" + std::to_string(i + 1) + "_m_s2";
      c.mass_tests.push_back(Dir() + "/mass" + std::to_string(i + 1) + ".csv");
      WriteFileAtomic(c.mass_tests.back(), ident::FormatHammerTestCsv(t, {acc}, "force1_n"));
    }
    return c;
  }();
  return chain;
}

IdentifyRun Identify(const std::string& force, const std::string& sensors,
                     bool mass_tests = false) {
  IdentifyRequest request = DefaultIdentifyRequest();
  request.modal_tests = {TheChain().recording};
  if (mass_tests) {
    // The mass tests' path: each mass from its own test, the springs fitted with it.
    for (std::size_t i = 0; i < 2; ++i) request.mass_tests.push_back({i, TheChain().mass_tests[i]});
    request.mass_springs = {"1=fit", "2=fit"};
  }
  request.modes.driving_point = "2";
  request.estimation.force = force;
  request.sensors = sensors;
  return RunIdentify(TheChain().nominal, request);
}

TEST(SensorCalibration, ALoadCellOffByEpsScalesEveryMassSpringAndDamper) {
  // Reference: closed form, m, k, c ∝ 1 / H ∝ force sensitivity (methods §16).
  constexpr double kEps = 0.016;
  const IdentifyRun a = Identify("force1_n", "");
  const IdentifyRun b = Identify("force1_n*" + std::to_string(1.0 + kEps), "");
  const ident::ChainParameters& pa = a.result.chain;
  const ident::ChainParameters& pb = b.result.chain;
  ASSERT_EQ(pa.masses_kg.size(), 2);
  for (Eigen::Index i = 0; i < 2; ++i) {
    EXPECT_NEAR(pb.masses_kg[i] / pa.masses_kg[i], 1.0 + kEps, 1e-6) << i;
    EXPECT_NEAR(pb.springs_n_per_m[i] / pa.springs_n_per_m[i], 1.0 + kEps, 1e-6) << i;
    EXPECT_NEAR(pb.dampers_ns_per_m[i] / pa.dampers_ns_per_m[i], 1.0 + kEps, 1e-5) << i;
  }
  // The modes do not move: no internal check can see the load cell's error.
  for (std::size_t m = 0; m < a.result.table.modes.size(); ++m) {
    EXPECT_NEAR(b.result.table.modes[m].omega_test / a.result.table.modes[m].omega_test, 1.0, 1e-9);
  }
}

TEST(SensorCalibration, TheIntervalsCarryAStatisticalAndACalibrationPart) {
  // A certificate's statement per sensor: U = 2 % (k = 2) for the load cell, 1 % (k = 2) and
  // 3 % (k = 3) for the accelerometers: u = 1 %, 0.5 %, 1 %.
  const std::string sensors = Dir() + "/sensors.json";
  WriteFileAtomic(sensors, R"({"format": "vibid-sensors", "version": 1, "channels": {
    "force1": {"unit": "N", "counts_per_unit": 4.096, "offset_counts": 2048, "full_scale": 500,
               "dof": 2, "sensitivity_uncertainty": 0.02, "coverage_factor": 2},
    "acc1": {"unit": "m/s2", "counts_per_unit": 10.24, "offset_counts": 2048, "full_scale": 200,
             "dof": 1, "sensitivity_uncertainty": 0.01, "coverage_factor": 2},
    "acc2": {"unit": "m/s2", "counts_per_unit": 10.24, "offset_counts": 2048, "full_scale": 200,
             "dof": 2, "sensitivity_uncertainty": 0.03, "coverage_factor": 3}}})");
  const IdentifyRun plain = Identify("force1_n", "", true);
  const IdentifyRun cal = Identify("force1_n", sensors, true);
  const double u[] = {std::hypot(0.01, 0.005), std::hypot(0.01, 0.01)};
  int checked = 0;
  for (std::size_t i = 0; i < 2; ++i) {
    const ident::PositionComparison& p = plain.result.table.positions[i];
    const ident::PositionComparison& c = cal.result.table.positions[i];
    const std::pair<const ident::Interval95*, const ident::Interval95*> pairs[] = {
        {&p.m_ci95, &c.m_ci95}, {&p.k_ci95, &c.k_ci95}, {&p.c_ci95, &c.c_ci95}};
    const double values[] = {c.m_updated, c.k_updated, c.c_updated};
    for (std::size_t q = 0; q < 3; ++q) {
      const ident::Interval95& stat = *pairs[q].first;
      const ident::Interval95& both = *pairs[q].second;
      if (!stat.Known()) {
        // No statistical interval: the calibration alone makes none.
        EXPECT_FALSE(both.Known()) << i << " " << q;
        continue;
      }
      ASSERT_TRUE(both.HasCalibration()) << i << " " << q;
      ++checked;
      EXPECT_DOUBLE_EQ(both.statistical_half_width, stat.HalfWidth());
      EXPECT_NEAR(both.calibration_half_width, 1.959963984540054 * u[i] * std::abs(values[q]),
                  1e-12 * std::abs(values[q]));
      EXPECT_NEAR(both.HalfWidth(), std::hypot(stat.HalfWidth(), both.calibration_half_width),
                  1e-12 * std::abs(values[q]));
      EXPECT_NEAR(0.5 * (both.lo + both.hi), 0.5 * (stat.lo + stat.hi),
                  1e-12 * std::abs(values[q]));
      EXPECT_NE(both.basis.find("calibration of force1 and acc" + std::to_string(i + 1)),
                std::string::npos)
          << both.basis;
    }
  }
  // The mass tests give every mass an interval (and the modal test k and c theirs).
  EXPECT_GE(checked, 2) << plain.result.table.positions[0].m_ci95.missing << " | "
                        << plain.result.method;
  // The JSON states both parts beside the interval.
  nlohmann::json j;
  PutInterval(j, "m_kg", cal.result.table.positions[0].m_ci95);
  if (cal.result.table.positions[0].m_ci95.Known()) {
    EXPECT_TRUE(j.contains("m_kg_ci95_statistical_half_width")) << j.dump();
    EXPECT_TRUE(j.contains("m_kg_ci95_calibration_half_width")) << j.dump();
  }
}

TEST(SensorCalibration, ASensorWithoutAStatedUncertaintyIsNamed) {
  device::SensorSet set{};
  device::SensorScaling force;
  force.unit = wire::Unit::kNewton;
  force.sensitivity_uncertainty = 0.02;
  set[static_cast<std::size_t>(wire::Channel::kForce1)] = force;
  std::vector<std::string> warnings;
  const std::vector<PositionCalibration> p =
      CalibrationOfPositions(set, "force1_n", {"acc1_m_s2", "x1_m:mm"}, warnings);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_DOUBLE_EQ(p[0].relative_u, 0.01);  // the load cell's alone
  EXPECT_EQ(p[1].sensors, "force1 and x1");
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("no sensitivity uncertainty for acc1"), std::string::npos)
      << warnings[0];
  // The certificate's values are checked.
  const auto refused = [](const std::string& channel, const std::string& part) {
    try {
      (void)device::SensorsFromJson(
          nlohmann::json::parse(
              R"({"format": "vibid-sensors", "version": 1, "channels": {"force1": )" + channel +
              "}}"),
          "s.json");
      ADD_FAILURE() << channel;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refused(R"({"unit": "N", "counts_per_unit": 4, "full_scale": 500, "sensitivity_uncertainty": 2})",
          "sensitivity_uncertainty must be a relative uncertainty in [0, 1)");
  refused(R"({"unit": "N", "counts_per_unit": 4, "full_scale": 500, "coverage_factor": 2})",
          "coverage_factor is given without sensitivity_uncertainty");
  refused(R"({"unit": "N", "counts_per_unit": 4, "full_scale": 500,
              "sensitivity_uncertainty": 0.02, "coverage_factor": 0.5})",
          "coverage_factor must be the certificate's k");
}

}  // namespace
}  // namespace vibid::workflow
