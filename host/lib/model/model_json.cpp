#include "vibid/model/model_json.hpp"

#include <cmath>
#include <string>

#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid::model {
namespace {

using nlohmann::json;

double Number(const json& value, const std::string& where) {
  Require(value.is_number(), where + " must be a number");
  const double x = value.get<double>();
  Require(std::isfinite(x), where + " must be finite");
  return x;
}

Eigen::VectorXd Vector(const json& object, const char* field, const std::string& source,
                       bool required) {
  const std::string where = source + ": field \"" + field + "\"";
  if (!object.contains(field)) {
    Require(!required, where + " is missing");
    return {};
  }
  const json& value = object.at(field);
  Require(value.is_array(), where + " must be an array of numbers");
  Eigen::VectorXd out(static_cast<Eigen::Index>(value.size()));
  for (std::size_t i = 0; i < value.size(); ++i) {
    out[static_cast<Eigen::Index>(i)] = Number(value[i], where + "[" + std::to_string(i + 1) + "]");
  }
  return out;
}

Eigen::MatrixXd Matrix(const json& object, const char* field, const std::string& source) {
  const std::string where = source + ": field \"" + field + "\"";
  const json& value = object.at(field);
  Require(value.is_array() && !value.empty(), where + " must be a non-empty array of rows");
  const std::size_t rows = value.size();
  Require(value[0].is_array(), where + " row 1 must be an array of numbers");
  const std::size_t cols = value[0].size();
  Eigen::MatrixXd out(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  for (std::size_t r = 0; r < rows; ++r) {
    const std::string row_where = where + " row " + std::to_string(r + 1);
    Require(value[r].is_array(), row_where + " must be an array of numbers");
    Require(value[r].size() == cols, row_where + " has " + std::to_string(value[r].size()) +
                                         " entries, row 1 has " + std::to_string(cols));
    for (std::size_t c = 0; c < cols; ++c) {
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
          Number(value[r][c], row_where + " column " + std::to_string(c + 1));
    }
  }
  return out;
}

json MatrixJson(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

// Builder errors do not know the file; prefix them so the user sees which model was wrong.
template <typename F>
Model WithSource(const std::string& source, F&& build) {
  try {
    return build();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

}  // namespace

Model ModelFromJson(const json& value, const std::string& source) {
  Require(value.is_object(), source + ": a model must be a JSON object");
  // Read (and so checked) whoever reads the model, kept by ModelFileFromJson.
  static_cast<void>(ModelVerdict(value, source));
  if (value.contains("topology")) {
    Require(value.at("topology").is_string(),
            source + ": field \"topology\" must be \"chain\" or \"cart\"");
    const std::string topology = value.at("topology").get<std::string>();
    if (topology == "chain") {
      RequireKnownKeys(value, {"topology", "masses", "springs", "dampers", "verdict"},
                       "model file " + source);
      const Eigen::VectorXd masses = Vector(value, "masses", source, true);
      const Eigen::VectorXd springs = Vector(value, "springs", source, true);
      const Eigen::VectorXd dampers = Vector(value, "dampers", source, false);
      return WithSource(source, [&] { return MakeChain(masses, springs, dampers); });
    }
    if (topology == "cart") {
      RequireKnownKeys(value, {"topology", "masses", "spring", "frictions", "verdict"},
                       "model file " + source);
      const Eigen::VectorXd masses = Vector(value, "masses", source, true);
      Require(value.contains("spring"), source + ": field \"spring\" is missing");
      const double k = Number(value.at("spring"), source + ": field \"spring\"");
      const Eigen::VectorXd frictions = Vector(value, "frictions", source, false);
      return WithSource(source, [&] { return MakeCartTrack(masses, k, frictions); });
    }
    throw InputError(source + ": field \"topology\" is \"" + Printable(topology) +
                     "\"; expected \"chain\" or \"cart\"");
  }
  // A slip in "topology" or "M" is named before the form is guessed from what is there.
  RequireKnownKeys(
      value,
      {"topology", "masses", "springs", "dampers", "spring", "frictions", "M", "C", "K", "verdict"},
      "model file " + source);
  Require(value.contains("M") && value.contains("K"),
          source + ": a model needs \"topology\" (chain or cart) or the matrices \"M\" and \"K\"");
  RequireKnownKeys(value, {"M", "C", "K", "verdict"}, "model file " + source);
  Model model;
  model.m_kg = Matrix(value, "M", source);
  model.k_n_per_m = Matrix(value, "K", source);
  model.c_ns_per_m = value.contains("C")
                         ? Matrix(value, "C", source)
                         : Eigen::MatrixXd::Zero(model.m_kg.rows(), model.m_kg.rows());
  return WithSource(source, [&] {
    Validate(model);
    return model;
  });
}

json ModelToJson(const Model& model) {
  return json{{"M", MatrixJson(model.m_kg)},
              {"C", MatrixJson(model.c_ns_per_m)},
              {"K", MatrixJson(model.k_n_per_m)}};
}

Model LoadModel(const std::string& path) { return ModelFromJson(ReadJsonFile(path), path); }

Verdict ModelVerdict(const json& value, const std::string& source) {
  if (!value.is_object() || !value.contains("verdict")) {
    Verdict none;
    none.stated = false;
    return none;
  }
  return VerdictFromJson(value.at("verdict"), source + ": field \"verdict\"");
}

ModelFile ModelFileFromJson(const json& value, const std::string& source) {
  return {ModelFromJson(value, source), ModelVerdict(value, source), source};
}

ModelFile LoadModelFile(const std::string& path) {
  return ModelFileFromJson(ReadJsonFile(path), path);
}

void PutVerdict(json& model_file, const Verdict& verdict) {
  model_file["verdict"] = VerdictToJson(verdict);
}

}  // namespace vibid::model
