#include "vibid/bench/identify_routes.hpp"

#include <optional>

#include "vibid/bench/bench_files.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/ident/identify.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/workflow/identify_run.hpp"
#include "vibid/workflow/observer_design.hpp"

namespace vibid::bench {
namespace {

/// The page's explicit accept of a flagged result or model (a box the user ticks).
bool AcceptFlagged(const nlohmann::json& b) {
  if (!b.contains("accept_flagged")) return false;
  Require(b["accept_flagged"].is_boolean(), "'accept_flagged' must be true or false");
  return b["accept_flagged"].get<bool>();
}

nlohmann::json Identify(const BenchBoard& board, const std::string& directory,
                        const nlohmann::json& b) {
  Require(b.is_object(), "the request must be a JSON object");
  RequireKnownKeys(
      b, {"nominal", "mass_tests", "modal_tests", "output", "exp_window", "accept_flagged"},
      "the identify request");
  const bool accept_flagged = AcceptFlagged(b);
  Require(b.contains("nominal") && b.contains("modal_tests") && b.contains("output"),
          "the identify request needs nominal, modal_tests and output");
  workflow::IdentifyRequest request = workflow::DefaultIdentifyRequest();
  if (b.contains("exp_window")) {
    // `identify --exp-window`: the window's value at each hit record's end (the library checks
    // its range and names it).
    Require(b["exp_window"].is_number(), "'exp_window' must be a number (0: none)");
    request.estimation.impact_options.exp_window_end = b["exp_window"].get<double>();
  }
  if (b.contains("mass_tests")) {
    Require(b["mass_tests"].is_array(), "'mass_tests' must be a list of {position, file}");
    for (const nlohmann::json& t : b["mass_tests"]) {
      Require(t.is_object(), "each mass test must be {position, file}");
      RequireKnownKeys(t, {"position", "file"}, "a mass test");
      Require(t.contains("position") && t["position"].is_number_integer() &&
                  t["position"].get<long long>() >= 1,
              "a mass test's position must be a whole number from 1");
      Require(t.contains("file"), "a mass test needs its file");
      request.mass_tests.push_back({static_cast<std::size_t>(t["position"].get<long long>() - 1),
                                    FileIn(directory, t["file"], "mass_tests.file")});
    }
  }
  Require(b["modal_tests"].is_array() && !b["modal_tests"].empty(),
          "'modal_tests' must be a list of at least one file");
  for (const nlohmann::json& f : b["modal_tests"])
    request.modal_tests.push_back(FileIn(directory, f, "modal_tests"));
  const std::string output = OutputIn(directory, b["output"], "output");
  const model::Model nominal = model::LoadModel(FileIn(directory, b["nominal"], "nominal"));
  const auto n = static_cast<std::size_t>(nominal.dofs());
  // A chain longer than the accelerometers' default reach is measured as the board's record
  // places its sensors (the recordings are the board's, in its calibrated columns), and hit where
  // it places the hammer's load cell.
  if (n > 2 && board.ActiveCalibration() != nullptr) {
    const std::vector<std::string> columns =
        device::ResponseColumnsOnMasses(*board.ActiveCalibration(), n);
    for (std::size_t i = 0; i < columns.size(); ++i)
      request.modal_responses += (i > 0 ? "," : "") + columns[i];
    for (std::size_t t = 0; t < request.mass_tests.size(); ++t) {
      Require(request.mass_tests[t].position < n,
              "mass test " + std::to_string(t + 1) + ": position " +
                  std::to_string(request.mass_tests[t].position + 1) + " is beyond the model's " +
                  std::to_string(n) + " masses");
      request.mass_response += (t > 0 ? "," : "") + columns[request.mass_tests[t].position];
    }
  }
  // The record knows which mass the hammer's load cell is on: the modal responses are in mass
  // order, so that mass is the driving point, checked against the data by RunIdentify.
  if (board.ActiveCalibration() != nullptr) {
    if (const std::optional<std::size_t> mass = device::HammerMass(*board.ActiveCalibration());
        mass && *mass < n) {
      request.modes.driving_point = std::to_string(*mass + 1);
      request.modes.driving_point_source = device::HammerMassSource(*mass);
    }
  }
  const workflow::IdentifyRun run = workflow::RunIdentify(nominal, request);
  nlohmann::json out = workflow::IdentifyReportJson(run, n);
  out["table"] = workflow::ValidationText(run);
  out["output"] = b["output"];
  // A flagged result is shown, verdict first, but its model is written only with the page's
  // explicit accept (as `identify --accept-flagged`); the answer says which.
  out["written"] = !run.result.verdict.Flagged() || accept_flagged;
  if (out["written"].get<bool>())
    workflow::WriteUpdatedModel(run, n, output, true, "");
  else
    out["not_written"] = "the identification is flagged: " + b["output"].get<std::string>() +
                         " was not written; tick the accept box and identify again to write it "
                         "anyway, the file then carrying the verdict";
  return out;
}

nlohmann::json Design(BenchBoard& board, const std::string& directory, const nlohmann::json& b) {
  Require(b.is_object(), "the request must be a JSON object");
  RequireKnownKeys(b, {"model", "output", "fs_hz", "force_fs_n", "accept_flagged"},
                   "the design request");
  Require(b.contains("model") && b.contains("output"), "the design request needs model and output");
  workflow::ObserverDesignRequest request;
  const auto number = [&](const char* key, double& value) {
    if (!b.contains(key)) return false;
    Require(b[key].is_number(), std::string("'") + key + "' must be a number");
    value = b[key].get<double>();
    return true;
  };
  number("fs_hz", request.fs_hz);
  if (!number("force_fs_n", request.force_fs_n)) {
    request.force_fs_n =
        device::CalibratedFullScale(board.ActiveCalibration(), wire::Channel::kForce1)
            .value_or(request.force_fs_n);
  }
  const std::string output = OutputIn(directory, b["output"], "output");
  const model::ModelFile file = model::LoadModelFile(FileIn(directory, b["model"], "model"));
  RequireUsable(file.verdict, AcceptFlagged(b), "model file " + b["model"].get<std::string>(),
                "the design", "the page's accept box (\"accept_flagged\": true)");
  const model::Model& model = file.model;
  // A chain longer than two masses: the observer where the board's record puts the hammer's load
  // cell, fed by the sensor there (the CLI's defaults, mass 2 and an encoder, fit two masses).
  const std::optional<device::ObserverPlacement> placement =
      board.ActiveCalibration() != nullptr ? device::ObserverPlacementOf(*board.ActiveCalibration())
                                           : std::nullopt;
  if (model.dofs() > 2 && placement) {
    request.input_dof = request.output_dof = placement->dof;
    request.sensor = placement->sensor;
    request.sensor_fs = placement->sensor_fs;
  }
  const dob::DobDesign design = workflow::DesignObserverFor(model, request);
  WriteJsonFile(output, dob::DesignToJson(design));
  nlohmann::json verdict = VerdictToJson(file.verdict);
  verdict["text"] = FormatVerdict(file.verdict);
  return {{"summary", workflow::DesignSummary(design)},
          {"verdict", verdict},
          {"force_fs_n", request.force_fs_n},
          {"fs_hz", request.fs_hz},
          {"checksum", design.fixed.description.checksum},
          {"output", b["output"]}};
}

}  // namespace

void AddIdentifyRoutes(BenchServer& server, BenchBoard& board, const std::string& directory) {
  server.AddJsonRoute("cal/identify", [&board, directory](const nlohmann::json& b) {
    return Identify(board, directory, b);
  });
  server.AddJsonRoute("cal/design", [&board, directory](const nlohmann::json& b) {
    return Design(board, directory, b);
  });
}

}  // namespace vibid::bench
