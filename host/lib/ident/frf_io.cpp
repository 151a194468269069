#include "vibid/ident/frf_io.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid::ident {

namespace {

constexpr std::string_view kMetaTag = "# vibid-frf";
constexpr std::string_view kUffMetaTag = "vibid-frf";

std::string Trim(std::string_view s) {
  std::size_t a = 0;
  std::size_t b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r' || s[b - 1] == '\n'))
    --b;
  return std::string(s.substr(a, b - a));
}

bool EndsWith(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

double ToDouble(const std::string& s, const std::string& what) {
  double v = 0.0;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  const auto r = std::from_chars(b, e, v);
  Require(r.ec == std::errc() && r.ptr == e && std::isfinite(v),
          what + ": '" + Printable(s) + "' is not a finite number");
  return v;
}

long ToLong(const std::string& s, const std::string& what) {
  long v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  Require(r.ec == std::errc() && r.ptr == s.data() + s.size(),
          what + ": '" + Printable(s) + "' is not an integer");
  return v;
}

std::string Fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// The metadata items "key=value ..." of an FRF file (the CSV's first line, the UFF58 file's ID
// lines) into `frf`; unknown keys are skipped (a later version's). True when "measured" is given.
bool ApplyFrfMetadata(const std::string& items, const std::string& where, Frf& frf) {
  bool measured_given = false;
  std::istringstream in(items);
  std::string kv;
  while (in >> kv) {
    const auto eq = kv.find('=');
    Require(eq != std::string::npos,
            where + ": metadata item '" + Printable(kv) + "' is not key=value");
    const std::string key = kv.substr(0, eq);
    const std::string value = kv.substr(eq + 1);
    if (key == "kind")
      frf.quantity = ParseQuantity(value);
    else if (key == "estimator")
      frf.estimator = ParseEstimator(value);
    else if (key == "averages") {
      const long averages = ToLong(value, where + ": averages");
      Require(averages >= 0, where + ": averages must not be negative");
      frf.averages = static_cast<std::size_t>(averages);
    } else if (key == "exp_window_tau_s") {
      frf.exp_window_tau_s = ToDouble(value, where + ": exp_window_tau_s");
      // 0 is "no window"; a negative time constant would silently mean the same.
      Require(frf.exp_window_tau_s >= 0.0, where + ": exp_window_tau_s must not be negative");
    } else if (key == "pretrigger_s") {
      frf.pretrigger_s = ToDouble(value, where + ": pretrigger_s");
      Require(frf.pretrigger_s >= 0.0, where + ": pretrigger_s must not be negative");
    } else if (key == "record_s") {
      frf.record_s = ToDouble(value, where + ": record_s");
      Require(frf.record_s >= 0.0, where + ": record_s must not be negative");
    } else if (key == "measured") {
      frf.measured = ParseQuantity(value);
      measured_given = true;
    } else if (key == "force")
      frf.force_name = value;
  }
  return measured_given;
}

}  // namespace

namespace {

std::vector<std::string> FrfColumnNames(const Frf& frf) {
  std::vector<std::string> names{"freq_hz"};
  for (Eigen::Index j = 0; j < frf.h.cols(); ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const std::string base =
        ju < frf.response_names.size() ? frf.response_names[ju] : "h" + std::to_string(j + 1);
    names.push_back(base + "_re");
    names.push_back(base + "_im");
    names.push_back(base + "_coh");
  }
  return names;
}

}  // namespace

std::string FormatFrfCsv(const Frf& frf) {
  std::vector<Eigen::VectorXd> cols{frf.freq_hz};
  for (Eigen::Index j = 0; j < frf.h.cols(); ++j) {
    cols.push_back(frf.h.col(j).real());
    cols.push_back(frf.h.col(j).imag());
    cols.push_back(frf.coherence.col(j));
  }
  // One header row and rows: pandas.read_csv and numpy.genfromtxt open it with their defaults.
  return FormatCsv(FrfColumnNames(frf), cols);
}

std::string FrfSidecarPath(const std::string& csv_path) { return csv_path + ".json"; }

std::string FormatFrfSidecar(const Frf& frf) {
  nlohmann::ordered_json j;
  j["format"] = "vibid-frf";
  j["version"] = 1;
  j["columns"] = FrfColumnNames(frf);
  j["kind"] = FrfKindName(frf.quantity);
  j["estimator"] = EstimatorName(frf.estimator);
  j["averages"] = frf.averages;
  j["exp_window_tau_s"] = frf.exp_window_tau_s;
  j["pretrigger_s"] = frf.pretrigger_s;
  j["record_s"] = frf.record_s;
  j["measured"] = FrfKindName(frf.measured);
  // An FRF read without a force name is written without one, so it reads back as it was.
  if (!frf.force_name.empty()) j["force"] = frf.force_name;
  // Impact FRFs: where the hammer's force excites the structure (modes are sought there).
  if (frf.force_band_max_hz > 0.0)
    j["force_band_hz"] = {frf.force_band_min_hz, frf.force_band_max_hz};
  return j.dump(2) + "\n";
}

void ApplyFrfSidecar(std::string_view json, const std::string& source, Frf& frf) {
  const nlohmann::json j = ParseJsonText(json, source);
  Require(j.is_object() && j.value("format", nlohmann::json()) == "vibid-frf",
          source + ": not a vibid-frf sidecar (\"format\": \"vibid-frf\")");
  Require(j.value("version", nlohmann::json()) == 1,
          source + ": version " + j.value("version", nlohmann::json()).dump() +
              " is not one this vibid reads (1)");
  RequireKnownKeys(
      j,
      {"format", "version", "columns", "kind", "estimator", "averages", "exp_window_tau_s",
       "pretrigger_s", "record_s", "measured", "force", "force_band_hz"},
      source);
  const std::vector<std::string> names = FrfColumnNames(frf);
  Require(j.contains("columns") && j.at("columns") == nlohmann::json(names),
          source + ": describes columns " + j.value("columns", nlohmann::json()).dump() +
              ", the FRF's are " + nlohmann::json(names).dump() +
              ": it belongs to another file; remove it or put the FRF's own beside it");
  // The same items as the comment line of files written before the sidecar, with their checks.
  std::ostringstream items;
  items.precision(17);
  for (const char* key : {"kind", "estimator", "measured", "force"}) {
    if (!j.contains(key)) continue;
    // A word as the comment line takes it: no white space (an '=' inside the value is the
    // value's, as the comment line's reader has always kept it).
    Require(j.at(key).is_string() &&
                j.at(key).get<std::string>().find_first_of(" \t\n\r\v\f") == std::string::npos,
            source + ": \"" + key + "\" must be a word, not " + j.at(key).dump());
    items << " " << key << "=" << j.at(key).get<std::string>();
  }
  for (const char* key : {"averages", "exp_window_tau_s", "pretrigger_s", "record_s"}) {
    if (!j.contains(key)) continue;
    Require(j.at(key).is_number(), source + ": \"" + key + "\" must be a number");
    items << " " << key << "=" << j.at(key).dump();
  }
  const bool measured_given = ApplyFrfMetadata(items.str(), source, frf);
  if (!measured_given) frf.measured = frf.quantity;
  if (j.contains("force_band_hz")) {
    const nlohmann::json& b = j.at("force_band_hz");
    Require(
        b.is_array() && b.size() == 2 && b[0].is_number() && b[1].is_number() &&
            b[0].get<double>() >= 0.0 && b[1].get<double>() > b[0].get<double>(),
        source + ": \"force_band_hz\" must be [lo, hi] in Hz with 0 <= lo < hi, not " + b.dump());
    frf.force_band_min_hz = b[0].get<double>();
    frf.force_band_max_hz = b[1].get<double>();
  }
}

bool LooksLikeFrfCsv(std::string_view text) {
  if (text.substr(0, kMetaTag.size()) == kMetaTag) return true;
  return text.substr(0, 8) == "freq_hz,";
}

Frf ParseFrfCsv(std::string_view text, const std::string& source) {
  Frf frf;
  bool measured_given = false;
  if (text.substr(0, kMetaTag.size()) == kMetaTag) {
    const std::string line(text.substr(0, text.find('\n')));
    measured_given = ApplyFrfMetadata(line.substr(kMetaTag.size()), source + ": line 1", frf);
  }
  // A file without it was written before it was recorded: its own kind is the best guess.
  if (!measured_given) frf.measured = frf.quantity;
  const CsvTable table = ParseCsv(text, source);
  Require(table.Has("freq_hz"), source + ": an FRF file needs a freq_hz column");
  frf.freq_hz = table.Column("freq_hz");
  Require(frf.freq_hz.size() >= 4, source + ": an FRF needs at least 4 frequency lines");
  for (Eigen::Index i = 1; i < frf.freq_hz.size(); ++i) {
    Require(frf.freq_hz[i] > frf.freq_hz[i - 1],
            source + ": freq_hz must increase (row " + std::to_string(i + 1) + ")");
  }
  std::vector<std::string> bases;
  for (const std::string& n : table.names) {
    if (EndsWith(n, "_re")) bases.push_back(n.substr(0, n.size() - 3));
  }
  Require(!bases.empty(), source + ": no NAME_re/NAME_im column pair");
  frf.h.resize(frf.freq_hz.size(), static_cast<Eigen::Index>(bases.size()));
  frf.coherence =
      Eigen::MatrixXd::Ones(frf.freq_hz.size(), static_cast<Eigen::Index>(bases.size()));
  for (std::size_t j = 0; j < bases.size(); ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    Require(table.Has(bases[j] + "_im"),
            source + ": column " + bases[j] + "_re has no " + bases[j] + "_im");
    frf.h.col(jj).real() = table.Column(bases[j] + "_re");
    frf.h.col(jj).imag() = table.Column(bases[j] + "_im");
    if (table.Has(bases[j] + "_coh")) {
      frf.coherence.col(jj) = table.Column(bases[j] + "_coh");
      for (Eigen::Index i = 0; i < frf.coherence.rows(); ++i) {
        const double c = frf.coherence(i, jj);
        Require(c >= 0.0 && c <= 1.0, source + ": row " + std::to_string(i + 1) + ": " + bases[j] +
                                          "_coh is not a coherence in [0, 1]");
      }
    }
    frf.response_names.push_back(bases[j]);
  }
  return frf;
}

namespace {

int OrdinateType(Quantity q) {
  switch (q) {
    case Quantity::kDisplacement: return 8;
    case Quantity::kVelocity: return 11;
    case Quantity::kAcceleration: return 12;
  }
  return 0;
}

void WriteHeader(std::ostringstream& out, const std::string& id1,
                 const std::vector<std::string>& id_lines, int func_type, int rsp_node,
                 int ref_node, int ord_data_type, std::size_t points, double x0, double dx,
                 int ord_spec, int ord_len_exp) {
  char line[256];
  out << "    -1\n    58" << std::string(74, ' ') << "\n";
  std::snprintf(line, sizeof line, "%-80.80s\n", id1.c_str());
  out << line;
  for (std::size_t k = 0; k < 4; ++k) {
    std::snprintf(line, sizeof line, "%-80.80s\n",
                  k < id_lines.size() ? id_lines[k].c_str() : "NONE");
    out << line;
  }
  std::snprintf(line, sizeof line, "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d\n", func_type, 0, 0, 0,
                "NONE", rsp_node, 1, "NONE", ref_node, 1);
  out << line;
  std::snprintf(line, sizeof line, "%10d%10zu%10d%13.5E%13.5E%13.5E\n", ord_data_type, points, 1,
                x0, dx, 0.0);
  out << line;
  std::snprintf(line, sizeof line, "%10d%5d%5d%5d %-20s %-20s\n", 18, 0, 0, 0, "Frequency", "Hz");
  out << line;
  std::snprintf(line, sizeof line, "%10d%5d%5d%5d %-20s %-20s\n", ord_spec, ord_len_exp, 0, 0,
                "Response", "m");
  out << line;
  std::snprintf(line, sizeof line, "%10d%5d%5d%5d %-20s %-20s\n", func_type == 4 ? 13 : 0, 0,
                func_type == 4 ? 1 : 0, 0, func_type == 4 ? "Force" : "NONE",
                func_type == 4 ? "N" : "NONE");
  out << line;
  std::snprintf(line, sizeof line, "%10d%5d%5d%5d %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
  out << line;
}

// ID lines 2 to 5 (80 characters each): "vibid-frf" and the FRF's metadata as the CSV's first line
// has it, plus the exact abscissa (the header's E13.5 fields keep 6 digits), so that a file read
// back analyses as the CSV of the same estimate does (the pretrigger's ringing terms, the
// exponential window's damping). An item that does not fit (a long force name) is left out.
std::vector<std::string> MetadataIdLines(const Frf& frf, double x0, double dx) {
  std::vector<std::string> items;
  const auto num = [](const char* key, double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%s=%.17g", key, v);
    return std::string(text);
  };
  items.push_back(std::string("estimator=") + EstimatorName(frf.estimator));
  items.push_back("averages=" + std::to_string(frf.averages));
  items.push_back(num("exp_window_tau_s", frf.exp_window_tau_s));
  items.push_back(num("pretrigger_s", frf.pretrigger_s));
  items.push_back(num("record_s", frf.record_s));
  items.push_back(std::string("measured=") + FrfKindName(frf.measured));
  items.push_back(num("x0_hz", x0));
  items.push_back(num("dx_hz", dx));
  if (!frf.force_name.empty() && frf.force_name.find_first_of(" \t\r\n") == std::string::npos)
    items.push_back("force=" + frf.force_name);
  std::vector<std::string> lines{std::string(kUffMetaTag)};
  for (const std::string& item : items) {
    if (lines.back().size() + 1 + item.size() <= 80) {
      lines.back() += " " + item;
    } else if (lines.size() < 4 && item.size() <= 80) {
      lines.push_back(item);
    }
  }
  return lines;
}

void WriteValues(std::ostringstream& out, const std::vector<double>& values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    out << Fmt("%20.12E", values[i]);
    if (i % 4 == 3 || i + 1 == values.size()) out << "\n";
  }
}

}  // namespace

std::string FormatUff58(const Frf& frf, int reference_node) {
  Require(frf.freq_hz.size() >= 2, "UFF58: an FRF needs at least 2 lines");
  const auto points = static_cast<std::size_t>(frf.freq_hz.size());
  const double x0 = frf.freq_hz[0];
  const double dx = (frf.freq_hz[frf.freq_hz.size() - 1] - x0) / static_cast<double>(points - 1);
  // Response j is node j + 1, unless every response is named "nodeN" with distinct N (as the
  // reader names them): then those nodes are kept, so a UFF58 file reads and writes back the same.
  std::vector<int> nodes;
  std::set<int> seen;
  for (const std::string& n : frf.response_names) {
    int node = 0;
    const char* digits = n.data() + std::min<std::size_t>(4, n.size());
    const auto r = std::from_chars(digits, n.data() + n.size(), node);
    if (!n.starts_with("node") || r.ec != std::errc() || r.ptr != n.data() + n.size() || node < 1 ||
        node > 999999999 || !seen.insert(node).second) {
      break;
    }
    nodes.push_back(node);
  }
  if (nodes.size() != static_cast<std::size_t>(frf.h.cols())) {
    nodes.clear();
    for (Eigen::Index j = 0; j < frf.h.cols(); ++j) nodes.push_back(static_cast<int>(j) + 1);
  }
  std::ostringstream out;
  const std::vector<std::string> meta = MetadataIdLines(frf, x0, dx);
  for (Eigen::Index j = 0; j < frf.h.cols(); ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const std::string name =
        ju < frf.response_names.size() ? frf.response_names[ju] : "h" + std::to_string(j + 1);
    WriteHeader(out, std::string(FrfKindName(frf.quantity)) + " " + name, meta, 4, nodes[ju],
                reference_node, 6, points, x0, dx, OrdinateType(frf.quantity), 1);
    std::vector<double> values;
    values.reserve(2 * points);
    for (std::size_t i = 0; i < points; ++i) {
      values.push_back(frf.h(static_cast<Eigen::Index>(i), j).real());
      values.push_back(frf.h(static_cast<Eigen::Index>(i), j).imag());
    }
    WriteValues(out, values);
    out << "    -1\n";
    WriteHeader(out, "coherence " + name, meta, 6, nodes[ju], reference_node, 4, points, x0, dx, 0,
                0);
    values.clear();
    for (std::size_t i = 0; i < points; ++i)
      values.push_back(frf.coherence(static_cast<Eigen::Index>(i), j));
    WriteValues(out, values);
    out << "    -1\n";
  }
  return out.str();
}

namespace {

std::vector<std::string> SplitLines(std::string_view text) {
  std::vector<std::string> lines;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    std::string l(text.substr(pos, end - pos));
    if (!l.empty() && l.back() == '\r') l.pop_back();
    lines.push_back(l);
    pos = end + 1;
  }
  return lines;
}

struct Uff58Dataset {
  int func_type = 0;
  int rsp_node = 0;
  int ord_spec = 0;
  std::string id1;
  std::vector<std::string> id_lines;  // ID lines 2 to 5
  std::size_t header_line = 0;        // record 1's line, for messages
  double x0 = 0.0;
  double dx = 0.0;
  std::vector<double> values;
  std::size_t points = 0;
  bool complex = false;
};

// The file's lines with fixed-column access and error locations.
struct UffText {
  std::vector<std::string> lines;
  const std::string& source;
  std::size_t text_size = 0;

  std::string Field(std::size_t ln, std::size_t at, std::size_t width) const {
    const std::string& l = lines[ln];
    return at >= l.size() ? std::string() : Trim(std::string_view(l).substr(at, width));
  }
  std::string Where(std::size_t ln) const { return source + ": line " + std::to_string(ln + 1); }
};

// Records 1 to 11 of a dataset 58 whose record 1 is line h.
void ParseUff58Header(const UffText& t, std::size_t h, Uff58Dataset& d, long& ord_type) {
  d.id1 = Trim(t.lines[h]);
  for (std::size_t k = 1; k <= 4; ++k) d.id_lines.push_back(Trim(t.lines[h + k]));
  d.func_type = static_cast<int>(ToLong(t.Field(h + 5, 0, 5), t.Where(h + 5) + ": function type"));
  const long rsp_node = ToLong(t.Field(h + 5, 41, 10), t.Where(h + 5) + ": response node");
  Require(rsp_node >= 1 && rsp_node <= 999999999,
          t.Where(h + 5) + ": the response node must be 1 to 999999999");
  d.rsp_node = static_cast<int>(rsp_node);
  ord_type = ToLong(t.Field(h + 6, 0, 10), t.Where(h + 6) + ": ordinate data type");
  const long points = ToLong(t.Field(h + 6, 10, 10), t.Where(h + 6) + ": number of points");
  // Bounded by what the text can hold (one value per character at most), so a header cannot
  // make the reader allocate more than the file's size.
  Require(points >= 2 && static_cast<std::size_t>(points) <= t.text_size,
          t.Where(h + 6) + ": number of points must be 2 or more and fit the file");
  d.points = static_cast<std::size_t>(points);
  const long even = ToLong(t.Field(h + 6, 20, 10), t.Where(h + 6) + ": abscissa spacing");
  Require(even == 1, t.Where(h + 6) + ": only evenly spaced abscissas are supported");
  d.x0 = ToDouble(t.Field(h + 6, 30, 13), t.Where(h + 6) + ": abscissa start");
  d.dx = ToDouble(t.Field(h + 6, 43, 13), t.Where(h + 6) + ": abscissa step");
  Require(d.dx > 0.0 && std::isfinite(d.x0 + d.dx * static_cast<double>(d.points - 1)),
          t.Where(h + 6) + ": the abscissa step must be positive and the frequencies finite");
  d.ord_spec = static_cast<int>(ToLong(t.Field(h + 8, 0, 10), t.Where(h + 8) + ": ordinate type"));
  Require(
      ord_type == 2 || ord_type == 4 || ord_type == 5 || ord_type == 6,
      t.Where(h + 6) + ": ordinate data type " + std::to_string(ord_type) + " is not 2, 4, 5 or 6");
  d.complex = ord_type == 5 || ord_type == 6;
}

// Dataset 58 between the delimiters on lines i and end.
Uff58Dataset ParseUff58Dataset(const UffText& t, std::size_t i, std::size_t end) {
  Require(t.lines[i + 1].size() < 7 || t.lines[i + 1][6] != 'b',
          t.Where(i + 1) + ": binary UFF58 (58b) is not supported");
  Require(end >= i + 14, t.Where(i) + ": dataset 58 header is incomplete");
  Uff58Dataset d;
  const std::size_t h = i + 2;  // record 1
  long ord_type = 0;
  ParseUff58Header(t, h, d, ord_type);
  const std::size_t width = (ord_type == 4 || ord_type == 6) ? 20 : 13;
  for (std::size_t ln = h + 11; ln < end; ++ln) {
    const std::string& l = t.lines[ln];
    for (std::size_t at = 0; at + 1 < l.size() + 1 && at < l.size(); at += width) {
      const std::string cell = Trim(std::string_view(l).substr(at, width));
      if (cell.empty()) continue;
      std::string c = cell;
      for (char& ch : c)
        if (ch == 'D' || ch == 'd') ch = 'E';
      d.values.push_back(ToDouble(c, t.Where(ln)));
    }
  }
  Require(d.values.size() == d.points * (d.complex ? 2u : 1u),
          t.Where(h) + ": dataset holds " + std::to_string(d.values.size()) +
              " values, header says " + std::to_string(d.points) +
              (d.complex ? " complex points" : " points"));
  return d;
}

// Every dataset 58 of the file; other datasets are skipped.
std::vector<Uff58Dataset> ReadUff58Datasets(const UffText& t) {
  std::vector<Uff58Dataset> sets;
  const std::vector<std::string>& lines = t.lines;
  std::size_t i = 0;
  while (i < lines.size()) {
    if (Trim(lines[i]) != "-1") {
      Require(Trim(lines[i]).empty(), t.Where(i) + ": expected a dataset delimiter '-1'");
      ++i;
      continue;
    }
    Require(i + 1 < lines.size(), t.Where(i) + ": file ends after a delimiter");
    const std::string type = t.Field(i + 1, 0, 6);
    std::size_t end = i + 2;
    while (end < lines.size() && Trim(lines[end]) != "-1") ++end;
    Require(end < lines.size(), t.Where(i) + ": dataset " + type + " has no closing '-1'");
    if (type == "58") sets.push_back(ParseUff58Dataset(t, i, end));
    i = end + 1;
  }
  return sets;
}

// Coherence datasets (function type 6, real) of the FRFs' response nodes fill their columns.
void AddUff58Coherence(const std::vector<Uff58Dataset>& sets,
                       const std::map<int, Eigen::Index>& column_of_node, std::size_t points,
                       const std::string& source, Frf& frf) {
  for (const Uff58Dataset& d : sets) {
    if (d.func_type != 6 || d.complex || d.points != points) continue;
    const auto it = column_of_node.find(d.rsp_node);
    if (it == column_of_node.end()) continue;
    for (std::size_t k = 0; k < d.points; ++k) {
      Require(d.values[k] >= 0.0 && d.values[k] <= 1.0,
              source + ": coherence of node " + std::to_string(d.rsp_node) + " is not in [0, 1]");
      frf.coherence(static_cast<Eigen::Index>(k), it->second) = d.values[k];
    }
  }
}

// The metadata a vibid file's ID lines carry (MetadataIdLines); files of other software, or
// written before, have none and keep the defaults. The exact abscissa replaces the header's
// 6-digit one where it agrees with it to those digits.
void ApplyUffMetadata(const Uff58Dataset& d, const std::string& source, Frf& frf) {
  if (d.id_lines.empty() || !d.id_lines[0].starts_with(kUffMetaTag)) return;
  std::string items = d.id_lines[0].substr(kUffMetaTag.size());
  for (std::size_t k = 1; k < d.id_lines.size(); ++k) {
    if (d.id_lines[k] != "NONE") items += " " + d.id_lines[k];
  }
  std::istringstream in(items);
  std::string known;
  double x0 = std::numeric_limits<double>::quiet_NaN();
  double dx = x0;
  const std::string where = source + ": dataset 58 ID lines";
  for (std::string kv; in >> kv;) {
    if (kv.starts_with("x0_hz=")) {
      x0 = ToDouble(kv.substr(6), where + ": x0_hz");
    } else if (kv.starts_with("dx_hz=")) {
      dx = ToDouble(kv.substr(6), where + ": dx_hz");
    } else {
      known += " " + kv;
    }
  }
  const Quantity kind = frf.quantity;  // the ordinate type says it
  if (ApplyFrfMetadata(known, where, frf) == false) frf.measured = kind;
  frf.quantity = kind;
  const auto agrees = [](double exact, double header) {
    return std::isfinite(exact) &&
           std::abs(exact - header) <= 1e-5 * std::max(std::abs(header), 1e-300);
  };
  if (agrees(dx, d.dx) && (agrees(x0, d.x0) || (x0 == 0.0 && d.x0 == 0.0))) {
    const auto n = static_cast<Eigen::Index>(d.points);
    for (Eigen::Index k = 0; k < n; ++k) frf.freq_hz[k] = x0 + dx * static_cast<double>(k);
  }
}

Frf FrfFromUff58(const std::vector<Uff58Dataset>& sets, const std::string& source) {
  Frf frf;
  std::map<int, Eigen::Index> column_of_node;
  std::vector<const Uff58Dataset*> frfs;
  for (const Uff58Dataset& d : sets) {
    if (d.func_type == 4 && d.complex) frfs.push_back(&d);
  }
  Require(!frfs.empty(), source + ": no FRF dataset (58, function type 4, complex)");
  const Uff58Dataset& first = *frfs.front();
  frf.freq_hz =
      Eigen::VectorXd::LinSpaced(static_cast<Eigen::Index>(first.points), first.x0,
                                 first.x0 + first.dx * static_cast<double>(first.points - 1));
  switch (first.ord_spec) {
    case 11: frf.quantity = Quantity::kVelocity; break;
    case 12: frf.quantity = Quantity::kAcceleration; break;
    default: frf.quantity = Quantity::kDisplacement; break;
  }
  frf.h.resize(static_cast<Eigen::Index>(first.points), static_cast<Eigen::Index>(frfs.size()));
  frf.coherence = Eigen::MatrixXd::Ones(frf.h.rows(), frf.h.cols());
  for (std::size_t j = 0; j < frfs.size(); ++j) {
    const Uff58Dataset& d = *frfs[j];
    Require(d.points == first.points && d.x0 == first.x0 && d.dx == first.dx &&
                d.ord_spec == first.ord_spec,
            source + ": FRF datasets differ in abscissa or ordinate type");
    for (std::size_t k = 0; k < d.points; ++k) {
      frf.h(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) = {d.values[2 * k],
                                                                           d.values[2 * k + 1]};
    }
    Require(column_of_node.emplace(d.rsp_node, static_cast<Eigen::Index>(j)).second,
            source + ": two FRF datasets for response node " + std::to_string(d.rsp_node));
    frf.response_names.push_back("node" + std::to_string(d.rsp_node));
  }
  AddUff58Coherence(sets, column_of_node, first.points, source, frf);
  frf.averages = 0;
  frf.measured = frf.quantity;
  ApplyUffMetadata(first, source, frf);
  return frf;
}

}  // namespace

Frf ParseUff58(std::string_view text, const std::string& source) {
  const UffText t{SplitLines(text), source, text.size()};
  return FrfFromUff58(ReadUff58Datasets(t), source);
}

namespace {

bool IsUffPath(const std::string& path) { return EndsWith(path, ".uff") || EndsWith(path, ".unv"); }

}  // namespace

Frf LoadFrf(const std::string& path) {
  const std::string text = ReadFileText(path);
  if (IsUffPath(path)) return ParseUff58(text, path);
  Frf frf = ParseFrfCsv(text, path);
  const std::string sidecar = FrfSidecarPath(path);
  if (std::filesystem::exists(sidecar)) ApplyFrfSidecar(ReadFileText(sidecar), sidecar, frf);
  return frf;
}

void WriteFrf(const Frf& frf, const std::string& path, int reference_node) {
  if (IsUffPath(path)) {
    WriteFileAtomic(path, FormatUff58(frf, reference_node));
    return;
  }
  // The sidecar first: a CSV is never left beside the metadata of another.
  WriteFileAtomic(FrfSidecarPath(path), FormatFrfSidecar(frf));
  WriteFileAtomic(path, FormatFrfCsv(frf));
}

std::string FormatFrfForPath(const Frf& frf, const std::string& path, int reference_node) {
  if (IsUffPath(path)) return FormatUff58(frf, reference_node);
  return FormatFrfCsv(frf);
}

}  // namespace vibid::ident
