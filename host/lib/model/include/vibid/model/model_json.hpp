// Model files (JSON). Three forms are accepted:
//   {"topology": "chain", "masses": [m1, ...], "springs": [k1, ...], "dampers": [c1, ...]}
//   {"topology": "cart",  "masses": [M1, ...], "spring": k, "frictions": [B1, ...]}
//   {"M": [[...], ...], "K": [[...], ...], "C": [[...], ...]}
// `dampers`, `frictions` and `C` are optional. Units: kg, N/m, N·s/m.
// Any form may carry "verdict": {"level", "reasons"} (common/verdict.hpp), which `identify` writes
// into the model it updates. A file without one reads as ok with `stated` false (a nominal model
// written by hand, or a model written before files carried verdicts).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "vibid/common/verdict.hpp"
#include "vibid/model/model.hpp"

namespace vibid::model {

/// Builds and validates a model. InputError naming `source` and the offending field otherwise.
Model ModelFromJson(const nlohmann::json& json, const std::string& source = "model");

/// The full-matrix form {"M", "C", "K"}; reads back bit-identical through ModelFromJson.
nlohmann::json ModelToJson(const Model& model);

/// Reads a model file; InputError naming the file (and line, for malformed JSON).
Model LoadModel(const std::string& path);

/// A model file as the steps that take a model to the board read it: the model and its verdict.
struct ModelFile {
  Model model;
  Verdict verdict;
  std::string source;  ///< The path (or name) it was read from.
};

/// The file's verdict (checked: InputError on a malformed one); none stated without the field.
Verdict ModelVerdict(const nlohmann::json& json, const std::string& source);
ModelFile ModelFileFromJson(const nlohmann::json& json, const std::string& source);
ModelFile LoadModelFile(const std::string& path);

/// Sets the file's "verdict" field.
void PutVerdict(nlohmann::json& model_file, const Verdict& verdict);

}  // namespace vibid::model
