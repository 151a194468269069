// Which columns of a recording or of the board's log a watch takes (`vibid watch`, Python's
// vibid.watch, the bench): the responses named, or by default every acceleration and position
// column, and the board's own model test (`model_g`, `model_stale`) when the log carries it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "vibid/workflow/watch_session.hpp"

namespace vibid::workflow {

struct WatchColumns {
  std::vector<std::string> responses;  ///< The columns watched, in the order fed.
  /// The board's CUSUM statistic and its latched flag (`model_g`, `model_stale`), both present or
  /// neither: fed with the responses (WatchSession::Feed with the board's columns).
  std::optional<std::string> board_statistic;
  std::optional<std::string> board_flag;
};

/// An acceleration (acc1_m_s2, acc2_counts...) or position (x1_m...) column.
bool IsWatchResponse(const std::string& name);

/// The watched columns of `names` (a recording's or a log's, time column aside): `requested` when
/// given (each must be there), else every acceleration and position column. InputError naming the
/// option in `spelling`, `source` (the file, or "the log"), the columns there and the way out.
WatchColumns ChooseWatchColumns(const std::vector<std::string>& names,
                                const std::vector<std::string>& requested,
                                const std::string& source, OptionSpelling spelling);

}  // namespace vibid::workflow
