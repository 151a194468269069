// The JSON of a live hammer test's state (result_json.hpp): what the bench's page draws.
#include <cmath>

#include "vibid/ident/spectral.hpp"
#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::workflow {

namespace {

nlohmann::json HitJson(const SessionHit& h) {
  return {{"index", h.index},
          {"t_s", h.t_s},
          {"peak_n", h.peak_n},
          {"verdict", h.verdict},
          {"reason", h.reason},
          {"accepted", h.accepted},
          {"decided_by", h.by_operator ? "operator" : "auto"}};
}

std::vector<double> Values(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

nlohmann::json FrfJson(const ident::Frf& frf) {
  nlohmann::json responses = nlohmann::json::array();
  for (std::size_t j = 0; j < frf.responses(); ++j) {
    const auto col = static_cast<Eigen::Index>(j);
    const Eigen::VectorXd magnitude = frf.h.col(col).cwiseAbs();
    const Eigen::VectorXd phase =
        frf.h.col(col).unaryExpr([](const std::complex<double>& z) { return std::arg(z); }).real();
    responses.push_back({{"name", j < frf.response_names.size() ? frf.response_names[j] : ""},
                         {"magnitude", Values(magnitude)},
                         {"phase_rad", Values(phase)},
                         {"coherence", Values(frf.coherence.col(col))}});
  }
  return {{"kind", ident::FrfKindName(frf.quantity)},
          {"force", frf.force_name},
          {"averages", frf.averages},
          {"freq_hz", Values(frf.freq_hz)},
          {"responses", responses}};
}

}  // namespace

nlohmann::json HitListJson(const std::vector<SessionHit>& hits) {
  nlohmann::json list = nlohmann::json::array();
  for (const SessionHit& h : hits) list.push_back(HitJson(h));
  return {{"format", kHitListFormat}, {"hits", list}};
}

nlohmann::json HammerSnapshotJson(const HammerSnapshot& s) {
  nlohmann::json j;
  j["version"] = s.version;
  j["samples"] = s.samples;
  j["fs_hz"] = s.fs_hz;
  j["finished"] = s.finished;
  j["pending_hits"] = s.pending_hits;
  j["accepted"] = s.accepted;
  j["hits"] = HitListJson(s.hits)["hits"];
  j["frf"] = s.frf.lines() > 0 ? FrfJson(s.frf) : nlohmann::json(nullptr);
  j["warnings"] = s.warnings;
  j["modes"] = s.modes ? ModesToJson(s.modes->modes)["modes"] : nlohmann::json(nullptr);
  j["diagram"] =
      s.modes && s.modes->has_diagram ? DiagramToJson(s.modes->diagram) : nlohmann::json(nullptr);
  j["modes_error"] = s.modes_error;
  j["band_hz"] = s.band_max_hz > 0.0 ? nlohmann::json::array({s.band_min_hz, s.band_max_hz})
                                     : nlohmann::json(nullptr);
  j["timing_ms"] = {{"update", s.last_update_ms}, {"modes", s.last_modes_ms}};
  return j;
}

nlohmann::json HitTracesJson(const HitTraces& t) {
  nlohmann::json responses = nlohmann::json::array();
  for (Eigen::Index j = 0; j < t.responses.cols(); ++j) {
    const auto k = static_cast<std::size_t>(j);
    responses.push_back({{"name", k < t.response_names.size() ? t.response_names[k] : ""},
                         {"values", Values(t.responses.col(j))}});
  }
  return {{"index", t.index},
          {"t_s", Values(t.t_s)},
          {"force", Values(t.force)},
          {"force_window", Values(t.force_window)},
          {"responses", responses}};
}

}  // namespace vibid::workflow
