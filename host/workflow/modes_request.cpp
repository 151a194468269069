#include "vibid/workflow/modes_request.hpp"

#include <optional>

#include "vibid/common/error.hpp"
#include "vibid/common/option_text.hpp"

namespace vibid::workflow {

std::size_t ResolveDrivingPoint(const ident::Frf& frf, const std::string& spec) {
  for (std::size_t j = 0; j < frf.response_names.size(); ++j) {
    if (frf.response_names[j] == spec) return j;
  }
  const std::optional<long long> index = ParseInteger(spec);
  Require(index && *index >= 1 && static_cast<std::size_t>(*index) <= frf.responses(),
          "--driving-point '" + spec + "' is neither a response name nor an index 1.." +
              std::to_string(frf.responses()));
  return static_cast<std::size_t>(*index - 1);
}

std::optional<ident::NamedDrivingPoint> NamedDrivingPointOf(const ident::Frf& frf,
                                                            const ModeRequest& request) {
  if (request.driving_point.empty()) return std::nullopt;
  return ident::NamedDrivingPoint{.index = ResolveDrivingPoint(frf, request.driving_point),
                                  .source = request.driving_point_source.empty()
                                                ? "--driving-point " + request.driving_point
                                                : request.driving_point_source};
}

namespace {

// Dry friction named where it spoils the modes: peaks with no mode may be modes it hides, and
// modes that are mostly peak picks of a broken fit are refused with friction as the cause.
void NameFriction(ident::ModeIdentification& r) {
  const std::string friction = ident::FrictionShownBy(r);
  if (friction.empty()) return;
  std::size_t unreliable = 0;
  for (const ident::ModeEstimate& m : r.modes) unreliable += m.unreliable ? 1 : 0;
  if (2 * unreliable > r.modes.size()) {
    throw InputError("no reliable modes: " + std::to_string(unreliable) + " of " +
                     std::to_string(r.modes.size()) + " are unreliable, and the recording's " +
                     friction.substr(4) +
                     ": dry friction stops the ring-downs, so the FRF is no viscous system's; "
                     "harder hits (friction's share falls as the amplitude grows), or the "
                     "time-domain routes that model friction (vibid decay, greybox)");
  }
  if (!r.peaks_without_mode_hz.empty()) {
    r.warnings.push_back("the recording's " + friction.substr(4) +
                         ": the peaks with no mode may be modes dry friction hides; harder hits "
                         "show them");
  }
}

bool RingDownsFit(const ident::Frf& frf, const ident::RingDowns* ringdowns) {
  return ringdowns != nullptr && !ringdowns->hits.empty() &&
         ringdowns->hits.front().cols() == static_cast<Eigen::Index>(frf.responses());
}

}  // namespace

ident::DrivingPointChoice ChooseDrivingPointOf(const ident::Frf& frf,
                                               const ident::ModeIdentification& provisional,
                                               const std::optional<ident::NamedDrivingPoint>& named,
                                               const ident::RingDowns* ringdowns) {
  try {
    return ident::ChooseDrivingPoint(ident::ModalConstantsOf(frf, provisional), named);
  } catch (const InputError& e) {
    // Only the refusal of a point the data do not single out: a named point the data contradict
    // is the user's slip, whatever else the test shows.
    if (named || !RingDownsFit(frf, ringdowns)) throw;
    // The friction check reads each mode's ring-down through the shapes' directions, which the
    // provisional point's scaling leaves alone (3-mass chain, 0.3 N per mass: one mode of three
    // in 5 of 40 seeds, refused with no word of friction before).
    ident::ModeIdentification checked = provisional;
    ident::ApplyAmplitudeCheck(*ringdowns, checked);
    const std::string friction = ident::FrictionShownBy(checked);
    if (friction.empty()) throw;
    throw InputError(std::string(e.what()) +
                     "; the likely cause is dry friction: the recording's " + friction.substr(4) +
                     ", and friction hides modes; harder hits (friction's share falls as the "
                     "amplitude grows), or the time-domain routes that model friction (vibid "
                     "decay, greybox)");
  }
}

ident::ModeIdentification IdentifyModes(const ident::Frf& receptance, const ModeRequest& request,
                                        const ident::RingDowns* ringdowns,
                                        ident::DrivingPointChoice* choice) {
  ident::ModeIdentificationOptions o = request.options;
  o.method = ident::ParseModeMethod(request.method);
  if (!request.orders.empty()) ident::ParseOrders(request.orders, o.stabilization);
  const std::optional<ident::NamedDrivingPoint> named = NamedDrivingPointOf(receptance, request);
  // The modal constants do not depend on the driving point (only the shapes' scaling does): the
  // modes are found once from a provisional point and scaled again when the choice differs.
  const std::size_t provisional = named ? named->index : 0;
  ident::ModeIdentification r = ident::IdentifyModes(receptance, provisional, o);
  ident::DrivingPointChoice chosen = ChooseDrivingPointOf(receptance, r, named, ringdowns);
  if (chosen.index != provisional) r = ident::IdentifyModes(receptance, chosen.index, o);
  r.warnings.insert(r.warnings.end(), chosen.warnings.begin(), chosen.warnings.end());
  if (choice != nullptr) *choice = std::move(chosen);
  if (RingDownsFit(receptance, ringdowns)) ident::ApplyAmplitudeCheck(*ringdowns, r);
  NameFriction(r);
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
  out.identification = IdentifyModes(out.frf, request, inputs.size() == 1 ? &ringdowns : nullptr,
                                     &out.driving_point);
  return out;
}

}  // namespace vibid::workflow
