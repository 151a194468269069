#include "vibid/workflow/watch_columns.hpp"

#include <algorithm>

#include "vibid/common/error.hpp"

namespace vibid::workflow {

bool IsWatchResponse(const std::string& name) {
  return name.rfind("acc", 0) == 0 ||
         (name.size() > 1 && name[0] == 'x' && name[1] >= '1' && name[1] <= '9');
}

WatchColumns ChooseWatchColumns(const std::vector<std::string>& names,
                                const std::vector<std::string>& requested,
                                const std::string& source, OptionSpelling spelling) {
  const auto has = [&](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  const std::string option = WatchOptionName("responses", spelling);
  WatchColumns out;
  if (!requested.empty()) {
    std::string known;
    for (const std::string& have : names) known += (known.empty() ? "" : ", ") + have;
    for (const std::string& n : requested) {
      Require(has(n), option + ": " + source + " has no column '" + n + "' (its columns: " + known +
                          "); name one of them");
      Require(std::count(out.responses.begin(), out.responses.end(), n) == 0,
              option + ": column '" + n + "' named twice; name each response once");
      out.responses.push_back(n);
    }
  } else {
    for (const std::string& n : names)
      if (IsWatchResponse(n)) out.responses.push_back(n);
    Require(!out.responses.empty(), "watch: " + source +
                                        " has no acceleration or position column; name the "
                                        "responses with " +
                                        option);
  }
  // The board's model test: fed as its flag only when both columns are there (a log written
  // with the test holds both).
  if (has("model_g") && has("model_stale")) {
    out.board_statistic = "model_g";
    out.board_flag = "model_stale";
  }
  return out;
}

}  // namespace vibid::workflow
