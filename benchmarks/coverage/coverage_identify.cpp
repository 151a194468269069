// The coverage study's identification on the library alone (vibid_ident), for machines where the
// whole `vibid` binary is not built: the path `vibid identify` and `vibid update mass` run with
// their defaults on a recording (impact FRF per hit with bad hits rejected, H1 of the
// accelerations, ring-downs for the amplitude check, receptance), and the same JSON keys as
// identify's report.json "parameters" and update mass's --json. chain_coverage.py --driver runs it.
//
//   coverage_identify identify NOMINAL.json DRIVING_POINT MODAL.csv [MASS_TEST.csv ...]
//   coverage_identify mass REC.csv NOMINAL_KG [EXP_WINDOW_END]
//
// Recordings: t_s, force1_n, acc1_m_s2, ... (a mass test's response is its only acc column).
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/identify.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/intervals.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/ident/updates.hpp"
#include "vibid/model/model_json.hpp"

namespace {

using namespace vibid;

struct Test {
  ident::Frf receptance;
  ident::RingDowns ringdowns;
  std::vector<std::string> warnings;
};

Test Estimate(const std::string& path, double exp_window_end = 0.0) {
  const CsvTable t = ReadCsv(path);
  const Eigen::VectorXd& time = t.Column("t_s");
  const double fs_hz = static_cast<double>(time.size() - 1) / (time[time.size() - 1] - time[0]);
  std::vector<std::size_t> acc;
  for (std::size_t i = 0; i < t.names.size(); ++i)
    if (t.names[i].rfind("acc", 0) == 0) acc.push_back(i);
  Eigen::MatrixXd resp(static_cast<Eigen::Index>(t.rows()), static_cast<Eigen::Index>(acc.size()));
  for (std::size_t j = 0; j < acc.size(); ++j)
    resp.col(static_cast<Eigen::Index>(j)) = t.columns[acc[j]];
  ident::ImpactOptions io;
  io.reject_bad_hits = true;
  io.exp_window_end = exp_window_end;
  const Eigen::VectorXd& force = t.Column("force1_n");
  const ident::ImpactResult r = ident::EstimateImpactFrf(
      force, resp, fs_hz, io, ident::Estimator::kH1, ident::Quantity::kAcceleration);
  Test out;
  out.ringdowns = ident::RingDownsOf(r, force, resp, fs_hz, ident::Quantity::kAcceleration);
  out.receptance = ident::ConvertFrf(r.frf, ident::Quantity::kDisplacement);
  out.warnings = r.warnings;
  return out;
}

void Put(nlohmann::json& j, const std::string& key, const ident::Interval95& ci) {
  if (ci.Known()) {
    j[key + "_ci95"] = {ci.lo, ci.hi};
    j[key + "_ci95_basis"] = ci.basis;
  } else {
    j[key + "_ci95"] = nullptr;
    j[key + "_ci95_missing"] = ci.missing;
  }
}

int Identify(int argc, char** argv) {
  Require(argc >= 5, "identify NOMINAL.json DRIVING_POINT MODAL.csv [MASS.csv ...]");
  const model::Model nominal = model::LoadModel(argv[2]);
  ident::IdentifyOptions o;
  o.driving_point = static_cast<std::size_t>(std::stoi(argv[3]) - 1);
  Test modal = Estimate(argv[4]);
  o.modal_ringdowns = {modal.ringdowns};
  std::vector<ident::MassTestInput> mass;
  for (int i = 5; i < argc; ++i)
    mass.push_back({static_cast<std::size_t>(i - 5), Estimate(argv[i]).receptance, 0.0, true});
  const ident::IdentifyResult r = ident::Identify(nominal, mass, {modal.receptance}, o);
  nlohmann::json params = nlohmann::json::array();
  for (std::size_t i = 0; i < r.table.positions.size(); ++i) {
    const ident::PositionComparison& p = r.table.positions[i];
    nlohmann::json j = {{"position", i + 1},
                        {"m_kg", p.m_updated},
                        {"k_n_per_m", p.k_updated},
                        {"c_ns_per_m", p.c_updated}};
    Put(j, "m_kg", p.m_ci95);
    Put(j, "k_n_per_m", p.k_ci95);
    Put(j, "c_ns_per_m", p.c_ci95);
    params.push_back(j);
  }
  nlohmann::json warnings = r.warnings;
  for (const auto& w : modal.warnings) warnings.push_back("modal test: " + w);
  const nlohmann::json out = {{"parameters", params},
                              {"warnings", warnings},
                              {"chi2", r.chain_fit.chi2},
                              {"dof", r.chain_fit.dof}};
  std::cout << out.dump() << "\n";
  return 0;
}

int Mass(int argc, char** argv) {
  Require(argc >= 4, "mass REC.csv NOMINAL_KG [EXP_WINDOW_END]");
  const Test t = Estimate(argv[2], argc > 4 ? std::stod(argv[4]) : 0.0);
  ident::MassUpdateOptions o;
  o.nominal_kg = std::stod(argv[3]);
  const ident::MassUpdateResult r = ident::UpdateMass(t.receptance, 0, o);
  nlohmann::json j = {{"mass_kg", r.mass_kg},
                      {"k_n_per_m", r.k_n_per_m},
                      {"c_ns_per_m", r.c_ns_per_m},
                      {"warnings", r.warnings}};
  Put(j, "mass_kg", ident::IntervalOf(r.mass_kg, r.mass_u));
  Put(j, "k_n_per_m", ident::IntervalOf(r.k_n_per_m, r.k_u));
  Put(j, "c_ns_per_m", ident::IntervalOf(r.c_ns_per_m, r.c_u));
  std::cout << j.dump() << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string what = argc > 1 ? argv[1] : "";
    if (what == "identify") return Identify(argc, argv);
    if (what == "mass") return Mass(argc, argv);
    std::cerr << "usage: coverage_identify identify|mass ...\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "coverage_identify: " << e.what() << "\n";
    return 1;
  }
}
