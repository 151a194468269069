#include "vibid/workflow/modes_request.hpp"

#include <optional>

#include "vibid/common/error.hpp"
#include "vibid/common/option_text.hpp"

namespace vibid::workflow {

std::size_t ResolveDrivingPoint(const ident::Frf& frf, const std::string& spec) {
  if (spec.empty()) return frf.responses() - 1;
  for (std::size_t j = 0; j < frf.response_names.size(); ++j) {
    if (frf.response_names[j] == spec) return j;
  }
  const std::optional<long long> index = ParseInteger(spec);
  Require(index && *index >= 1 && static_cast<std::size_t>(*index) <= frf.responses(),
          "--driving-point '" + spec + "' is neither a response name nor an index 1.." +
              std::to_string(frf.responses()));
  return static_cast<std::size_t>(*index - 1);
}

ident::ModeIdentification IdentifyModes(const ident::Frf& receptance, const ModeRequest& request,
                                        const ident::RingDowns* ringdowns) {
  ident::ModeIdentificationOptions o = request.options;
  o.method = ident::ParseModeMethod(request.method);
  if (!request.orders.empty()) ident::ParseOrders(request.orders, o.stabilization);
  ident::ModeIdentification r =
      ident::IdentifyModes(receptance, ResolveDrivingPoint(receptance, request.driving_point), o);
  if (ringdowns != nullptr && !ringdowns->hits.empty() &&
      ringdowns->hits.front().cols() == static_cast<Eigen::Index>(receptance.responses()))
    ident::ApplyAmplitudeCheck(*ringdowns, r);
  return r;
}

ModesOfInputs IdentifyModesOf(const std::vector<std::string>& inputs,
                              const EstimationOptions& estimation, const ModeRequest& request) {
  Require(estimation.kind == "receptance",
          "modes are identified from receptances; leave --kind at its default");
  ModesOfInputs out;
  std::vector<ident::Frf> frfs;
  ident::RingDowns ringdowns;
  for (const std::string& in : inputs) {
    Estimated e = LoadOrEstimate(in, estimation);
    const std::vector<std::string> lines = EstimationNotes(in, e);
    out.notes.insert(out.notes.end(), lines.begin(), lines.end());
    out.estimation_notes.push_back(e.note);
    out.estimation_warnings.push_back(e.warnings);
    ringdowns = std::move(e.ringdowns);
    frfs.push_back(std::move(e.frf));
  }
  out.frf = JoinColumns(frfs, inputs);
  out.identification = IdentifyModes(out.frf, request, inputs.size() == 1 ? &ringdowns : nullptr);
  return out;
}

}  // namespace vibid::workflow
