// The verdict a result carries (architecture decision 10): how far the library trusts what it
// computed, with its reasons, decided once in the library and mapped the same way by every front
// end (exit code, page prompt, Python exception). A model file written from an identification
// carries it, and every step that takes a model to the board checks it (RequireUsable).
//
// The levels, in rising order:
//   ok       nothing the library checks speaks against the result;
//   caution  usable, but something is unchecked or weak (said with the reason, exit 0);
//   flagged  the library's own checks say not to use it: not written and not taken to the board
//            unless the user accepts it explicitly (--accept-flagged, accept_flagged=True);
//   refused  no result at all (an InputError or NumericalError said why); a file never carries it
//            from vibid, and a file that says it is refused outright.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/common/error.hpp"

namespace vibid {

enum class VerdictLevel { kOk, kCaution, kFlagged, kRefused };

/// "ok", "caution", "flagged", "refused".
const char* VerdictLevelName(VerdictLevel level);
std::optional<VerdictLevel> ParseVerdictLevel(std::string_view name);

struct VerdictReason {
  VerdictLevel level = VerdictLevel::kCaution;
  /// Machine-readable, stable: "worse_than_nominal", "chain_fit_unchecked", ...
  std::string code;
  /// One sentence for the user: what is wrong and the way out.
  std::string text;
};

struct Verdict {
  VerdictLevel level = VerdictLevel::kOk;
  std::vector<VerdictReason> reasons;
  /// False for a model file that states no verdict (written by hand, or before files carried
  /// one): read as ok, and said so where the verdict is shown.
  bool stated = true;

  /// Adds a reason and raises the level to it (a verdict never falls).
  void Add(VerdictLevel reason_level, std::string code, std::string text);
  bool Flagged() const { return level == VerdictLevel::kFlagged; }
  bool Has(std::string_view code) const;
};

/// {"level": "flagged", "reasons": [{"level", "code", "text"}, ...]}.
nlohmann::json VerdictToJson(const Verdict& verdict);
/// The inverse; InputError naming `where` for a malformed one (an unknown level or key).
Verdict VerdictFromJson(const nlohmann::json& json, const std::string& where);

/// "FLAGGED: reason; reason" (the level in capitals, each reason's text), "OK" without reasons,
/// "OK (none stated)" for a file without one.
std::string FormatVerdict(const Verdict& verdict);

/// A flagged (or refused) input a step will not take unless told: the CLI exits with its own code
/// (kExitFlagged), Python raises FlaggedResultError, the bench asks for the explicit accept.
class FlaggedError : public InputError {
 public:
  explicit FlaggedError(const std::string& message) : InputError(message) {}
};

/// Refuses a flagged input unless `accept_flagged` (FlaggedError: "<what> is flagged (<reasons>):
/// <step> refuses it; <option> takes it anyway"); refuses a refused one always. `what` names the
/// input ("model file updated.json"), `step` the step ("cal upload"), `option` the way to accept
/// ("--accept-flagged").
void RequireUsable(const Verdict& verdict, bool accept_flagged, const std::string& what,
                   const std::string& step, const std::string& option);

}  // namespace vibid
