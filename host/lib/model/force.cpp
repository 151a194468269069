#include "vibid/model/force.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"

namespace vibid::model {
namespace {

struct KindInfo {
  const char* name;
  ShapeKind kind;
  std::vector<std::string> required;  // besides dof and amp
  std::vector<std::string> optional;
};

const std::vector<KindInfo>& Kinds() {
  static const std::vector<KindInfo> kinds = {
      {"step", ShapeKind::kStep, {}, {"t0"}},
      {"pulse", ShapeKind::kPulse, {"width"}, {"t0"}},
      {"halfsine", ShapeKind::kHalfSine, {"width"}, {"t0"}},
      {"sine", ShapeKind::kSine, {"freq_hz"}, {"t0"}},
      {"chirp", ShapeKind::kChirp, {"f0_hz", "f1_hz", "t1"}, {"t0"}},
  };
  return kinds;
}

double EdgeTolerance(double t_s) { return 1e-12 * std::max(1.0, std::abs(t_s)); }

std::string Trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return std::string(s.substr(first, last - first + 1));
}

}  // namespace

ForceShape ParseForceShape(std::string_view spec) {
  const std::string where = "force spec '" + std::string(spec) + "'";
  const auto colon = spec.find(':');
  Require(
      colon != std::string_view::npos,
      where + ": expected KIND:key=value,... with KIND one of step, pulse, halfsine, sine, chirp");
  const std::string kind_name = Trim(spec.substr(0, colon));
  const auto kind = std::find_if(Kinds().begin(), Kinds().end(),
                                 [&](const KindInfo& k) { return kind_name == k.name; });
  Require(kind != Kinds().end(), where + ": unknown kind '" + kind_name +
                                     "' (expected step, pulse, halfsine, sine or chirp)");

  std::map<std::string, double> values;
  std::string_view rest = spec.substr(colon + 1);
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string item = Trim(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const auto eq = item.find('=');
    Require(eq != std::string::npos && eq > 0, where + ": '" + item + "' is not key=value");
    const std::string key = Trim(std::string_view(item).substr(0, eq));
    const std::string text = Trim(std::string_view(item).substr(eq + 1));
    const bool known =
        key == "dof" || key == "amp" ||
        std::find(kind->required.begin(), kind->required.end(), key) != kind->required.end() ||
        std::find(kind->optional.begin(), kind->optional.end(), key) != kind->optional.end();
    Require(known, where + ": unknown key '" + key + "' for " + kind->name);
    Require(!values.contains(key), where + ": key '" + key + "' given twice");
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    Require(ec == std::errc() && end == text.data() + text.size() && std::isfinite(value),
            where + ": " + key + "='" + text + "' is not a finite number");
    values[key] = value;
  }
  const auto get = [&](const std::string& key) {
    Require(values.contains(key), where + ": missing key '" + key + "'");
    return values.at(key);
  };
  ForceShape shape;
  shape.kind = kind->kind;
  const double dof = get("dof");
  Require(dof >= 1.0 && dof == std::floor(dof) && dof < 1e6,
          where + ": dof must be an integer >= 1 (counted from 1)");
  shape.dof = static_cast<int>(dof) - 1;
  shape.amp_n = get("amp");
  shape.t0_s = values.contains("t0") ? values.at("t0") : 0.0;
  switch (shape.kind) {
    case ShapeKind::kStep: break;
    case ShapeKind::kPulse:
    case ShapeKind::kHalfSine:
      shape.width_s = get("width");
      Require(shape.width_s > 0.0, where + ": width must be > 0 s");
      break;
    case ShapeKind::kSine:
      shape.freq_hz = get("freq_hz");
      Require(shape.freq_hz > 0.0, where + ": freq_hz must be > 0");
      break;
    case ShapeKind::kChirp:
      shape.f0_hz = get("f0_hz");
      shape.f1_hz = get("f1_hz");
      shape.t1_s = get("t1");
      Require(shape.f0_hz >= 0.0 && shape.f1_hz >= 0.0, where + ": f0_hz and f1_hz must be >= 0");
      Require(shape.t1_s > 0.0, where + ": t1 must be > 0 s");
      break;
  }
  return shape;
}

double EvaluateShape(const ForceShape& shape, double t_s, Side side) {
  const double tau = t_s - shape.t0_s;
  // Edges are tested at a time nudged to the requested side; smooth values use the true time.
  const double tol = EdgeTolerance(t_s);
  const double edge_tau = side == Side::kFrom ? tau + tol : tau - tol;
  if (edge_tau < 0.0) return 0.0;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  switch (shape.kind) {
    case ShapeKind::kStep: return shape.amp_n;
    case ShapeKind::kPulse: return edge_tau < shape.width_s ? shape.amp_n : 0.0;
    case ShapeKind::kHalfSine:
      return edge_tau < shape.width_s
                 ? shape.amp_n * std::sin(std::numbers::pi * std::max(tau, 0.0) / shape.width_s)
                 : 0.0;
    case ShapeKind::kSine:
      return shape.amp_n * std::sin(kTwoPi * shape.freq_hz * std::max(tau, 0.0));
    case ShapeKind::kChirp:
      if (edge_tau >= shape.t1_s) return 0.0;
      return shape.amp_n *
             std::sin(kTwoPi * (shape.f0_hz * std::max(tau, 0.0) +
                                (shape.f1_hz - shape.f0_hz) * tau * tau / (2.0 * shape.t1_s)));
  }
  return 0.0;
}

ForceTable LoadForceTable(const std::string& path, int dofs) {
  const CsvTable csv = ReadCsv(path);
  Require(csv.Has("t_s"), path + ": force table needs a 't_s' column");
  ForceTable table;
  table.t_s = csv.Column("t_s");
  table.force_n = Eigen::MatrixXd::Zero(table.t_s.size(), dofs);
  int used = 0;
  for (int dof = 0; dof < dofs; ++dof) {
    const std::string name = "f" + std::to_string(dof + 1) + "_n";
    if (csv.Has(name)) {
      table.force_n.col(dof) = csv.Column(name);
      ++used;
    }
  }
  for (const std::string& name : csv.names) {
    Require(name == "t_s" || (name.size() > 3 && name[0] == 'f' && name.ends_with("_n")),
            path + ": unexpected column '" + name + "' (expected t_s and f1_n..f" +
                std::to_string(dofs) + "_n)");
  }
  Require(used + 1 == static_cast<int>(csv.names.size()),
          path + ": force columns must be f1_n..f" + std::to_string(dofs) + "_n for this model");
  return table;
}

void ValidateForceInput(const ForceInput& input, int dofs, const std::string& what) {
  for (const ForceShape& shape : input.shapes) {
    Require(shape.dof >= 0 && shape.dof < dofs, what + " dof " + std::to_string(shape.dof + 1) +
                                                    " is out of range 1.." + std::to_string(dofs));
    Require(std::isfinite(shape.amp_n) && std::isfinite(shape.t0_s),
            what + " amplitude and t0 must be finite");
  }
  const ForceTable& table = input.table;
  if (table.t_s.size() == 0) return;
  Require(table.force_n.rows() == table.t_s.size(),
          what + " table: force rows must match the time samples");
  Require(table.force_n.cols() == dofs,
          what + " table has " + std::to_string(table.force_n.cols()) + " columns, the model has " +
              std::to_string(dofs) + " DOFs");
  Require(table.t_s.allFinite() && table.force_n.allFinite(),
          what + " table has a non-finite value");
  for (Eigen::Index i = 1; i < table.t_s.size(); ++i) {
    Require(table.t_s[i] > table.t_s[i - 1],
            what + " table: t_s must increase strictly (row " + std::to_string(i + 1) + ")");
  }
}

void EvaluateForce(const ForceInput& input, double t_s, Eigen::Ref<Eigen::VectorXd> out,
                   Side side) {
  out.setZero();
  for (const ForceShape& shape : input.shapes) out[shape.dof] += EvaluateShape(shape, t_s, side);
  const ForceTable& table = input.table;
  const Eigen::Index rows = table.t_s.size();
  // The tolerance keeps a sample time written in decimal (0.003) and the same instant computed as
  // k·dt on the same side of each other.
  const double t_edge = side == Side::kFrom ? t_s + EdgeTolerance(t_s) : t_s - EdgeTolerance(t_s);
  if (rows == 0 || t_edge < table.t_s[0]) return;
  // Last sample at or before t: binary search, no allocation.
  const double* begin = table.t_s.data();
  const double* it = std::upper_bound(begin, begin + rows, t_edge);
  out += table.force_n.row((it - begin) - 1).transpose();
}

}  // namespace vibid::model
