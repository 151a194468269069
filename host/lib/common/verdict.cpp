#include "vibid/common/verdict.hpp"

#include <algorithm>
#include <cctype>

#include "vibid/common/enum_names.hpp"
#include "vibid/common/json_keys.hpp"

namespace vibid {
namespace {

constexpr EnumNames<VerdictLevel, 4> kLevelNames{{{VerdictLevel::kOk, "ok"},
                                                  {VerdictLevel::kCaution, "caution"},
                                                  {VerdictLevel::kFlagged, "flagged"},
                                                  {VerdictLevel::kRefused, "refused"}}};

VerdictLevel LevelAt(const nlohmann::json& j, const std::string& where) {
  Require(j.contains("level") && j["level"].is_string(),
          where + ": \"level\" must be one of ok, caution, flagged, refused");
  const std::optional<VerdictLevel> level = ParseVerdictLevel(j["level"].get<std::string>());
  Require(level.has_value(), where + ": \"level\" '" + j["level"].get<std::string>() +
                                 "' is not one of ok, caution, flagged, refused");
  return *level;
}

std::string Upper(const char* s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return out;
}

}  // namespace

const char* VerdictLevelName(VerdictLevel level) { return NameOf(kLevelNames, level, "unknown"); }

std::optional<VerdictLevel> ParseVerdictLevel(std::string_view name) {
  return FindByName(kLevelNames, name);
}

void Verdict::Add(VerdictLevel reason_level, std::string code, std::string text) {
  reasons.push_back({reason_level, std::move(code), std::move(text)});
  level = std::max(level, reason_level);
}

bool Verdict::Has(std::string_view code) const {
  return std::any_of(reasons.begin(), reasons.end(),
                     [code](const VerdictReason& r) { return r.code == code; });
}

nlohmann::json VerdictToJson(const Verdict& verdict) {
  nlohmann::json reasons = nlohmann::json::array();
  for (const VerdictReason& r : verdict.reasons)
    reasons.push_back({{"level", VerdictLevelName(r.level)}, {"code", r.code}, {"text", r.text}});
  return {{"level", VerdictLevelName(verdict.level)}, {"reasons", reasons}};
}

Verdict VerdictFromJson(const nlohmann::json& json, const std::string& where) {
  Require(json.is_object(), where + " must be an object {\"level\", \"reasons\"}");
  RequireKnownKeys(json, {"level", "reasons"}, where);
  Verdict v;
  const VerdictLevel stated = LevelAt(json, where);
  if (json.contains("reasons")) {
    Require(json["reasons"].is_array(), where + ": \"reasons\" must be a list");
    for (std::size_t i = 0; i < json["reasons"].size(); ++i) {
      const nlohmann::json& r = json["reasons"][i];
      const std::string at = where + " reason " + std::to_string(i + 1);
      Require(r.is_object(), at + " must be an object {\"level\", \"code\", \"text\"}");
      RequireKnownKeys(r, {"level", "code", "text"}, at);
      Require(r.contains("code") && r["code"].is_string() && r.contains("text") &&
                  r["text"].is_string(),
              at + " needs \"code\" and \"text\" strings");
      v.Add(LevelAt(r, at), r["code"].get<std::string>(), r["text"].get<std::string>());
    }
  }
  // The stated level stands even above its reasons (a file may be flagged by hand); one below
  // them is a contradiction the reader does not guess through.
  Require(stated >= v.level, where + ": \"level\" " + VerdictLevelName(stated) +
                                 " is below its reasons' (" + VerdictLevelName(v.level) + ")");
  v.level = stated;
  return v;
}

std::string FormatVerdict(const Verdict& verdict) {
  std::string out = Upper(VerdictLevelName(verdict.level));
  if (!verdict.stated) return out + " (none stated)";
  std::string sep = ": ";
  for (const VerdictReason& r : verdict.reasons) {
    out += sep + r.text;
    sep = "; ";
  }
  return out;
}

void RequireUsable(const Verdict& verdict, bool accept_flagged, const std::string& what,
                   const std::string& step, const std::string& option) {
  if (verdict.level == VerdictLevel::kRefused)
    throw FlaggedError(what + " is refused (" + FormatVerdict(verdict) + "): " + step +
                       " does not take it; identify again");
  if (verdict.level != VerdictLevel::kFlagged || accept_flagged) return;
  std::string reasons;
  for (const VerdictReason& r : verdict.reasons) {
    if (r.level < VerdictLevel::kFlagged) continue;
    reasons += (reasons.empty() ? "" : "; ") + r.text;
  }
  throw FlaggedError(what + " is flagged (" + (reasons.empty() ? "no reason stated" : reasons) +
                     "): " + step + " refuses it; " + option +
                     " takes it anyway, or identify again");
}

}  // namespace vibid
