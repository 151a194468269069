// Model files (JSON). Three forms are accepted:
//   {"topology": "chain", "masses": [m1, ...], "springs": [k1, ...], "dampers": [c1, ...]}
//   {"topology": "cart",  "masses": [M1, ...], "spring": k, "frictions": [B1, ...]}
//   {"M": [[...], ...], "K": [[...], ...], "C": [[...], ...]}
// `dampers`, `frictions` and `C` are optional. Units: kg, N/m, N·s/m.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "vibid/model/model.hpp"

namespace vibid::model {

/// Builds and validates a model. InputError naming `source` and the offending field otherwise.
Model ModelFromJson(const nlohmann::json& json, const std::string& source = "model");

/// The full-matrix form {"M", "C", "K"}; reads back bit-identical through ModelFromJson.
nlohmann::json ModelToJson(const Model& model);

/// Reads a model file; InputError naming the file (and line, for malformed JSON).
Model LoadModel(const std::string& path);

}  // namespace vibid::model
