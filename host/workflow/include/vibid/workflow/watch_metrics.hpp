// A watch's figures for Prometheus (the text exposition format, version 0.0.4): what a lab or a
// plant that watches several rigs scrapes from each `vibid watch` (--metrics-port) and from the
// bench (--metrics). Every family is a gauge (the blocks counted is the one counter), in base
// units (hertz, seconds, ratios), each sample labelled with its rig (and its mode, 1-based, for
// the modes). docs/watch.md lists the families; examples/prometheus/ scrapes, alerts and draws
// them.
//
// WatchMetricsText is the one place a figure of the watch becomes a metric: a field added to the
// session's blocks or its reference is exposed by one line there.
#pragma once

#include <chrono>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "vibid/workflow/watch_session.hpp"

namespace vibid::workflow {

/// The Content-Type of the exposition (the format's version 0.0.4).
inline constexpr const char* kMetricsContentType = "text/plain; version=0.0.4; charset=utf-8";

/// One watch as a scrape shows it.
struct WatchFigures {
  std::string rig;                          ///< The `rig` label (non-empty).
  WatchOptions options;                     ///< The options the watch runs with.
  std::optional<WatchReference> reference;  ///< Once built.
  std::optional<WatchBlock> last;           ///< The last block watched.
  long blocks = 0;                          ///< Blocks watched since the reference.
  std::optional<double> last_block_unix_s;  ///< Wall time the last block came (Unix seconds).
  bool running = false;                     ///< The watch is feeding (not ended or stopped).
};

/// The exposition of `watches` (each family once, its samples one per watch and mode): # HELP and
/// # TYPE lines, then `name{labels} value` lines; a figure a watch does not have yet (no
/// reference, no block, no board columns) is left out, never written as 0.
std::string WatchMetricsText(const std::vector<WatchFigures>& watches);

/// A label value as the format escapes it (\\, \" and \n).
std::string MetricsLabelValue(const std::string& value);

/// A watch's figures kept for scrapes that come from another thread than the watch's.
class WatchMetrics {
 public:
  /// `rig`: the label of every sample (InputError when empty).
  explicit WatchMetrics(std::string rig);

  /// A watch starts (its options; the previous watch's figures are dropped).
  void Start(const WatchOptions& options);
  void Reference(const WatchReference& reference);
  void Block(const WatchBlock& block);
  /// The watch ended (its last figures stay).
  void End();

  std::string Text() const;
  WatchFigures Figures() const;

 private:
  mutable std::mutex mutex_;
  WatchFigures figures_;
};

}  // namespace vibid::workflow
