#include "ident_cli.hpp"

#include <iostream>

#include "cli_support.hpp"

namespace vibid::cli {

void AddEstimationOptions(CLI::App* cmd, EstimationArgs& a, bool require_columns,
                          const std::string& kind_default) {
  a.kind = kind_default;
  auto* force =
      cmd->add_option("--force", a.force, "Force column of the recording, NAME[:UNIT|*FACTOR] (N)");
  auto* resp = cmd->add_option("--response", a.responses,
                               "Response column(s), comma separated, NAME[:UNIT|*FACTOR]");
  if (require_columns) {
    force->required();
    resp->required();
  }
  cmd->add_option("--estimator", a.estimator,
                  "FRF estimator: h1 (noise on the output), h2 (noise on the input), hv")
      ->capture_default_str();
  auto* impact = cmd->add_flag(
      "--impact", a.impact,
      "Hammer test: one record per detected hit, force and exponential windows (the default when\n"
      "the force is a train of short pulses)");
  cmd->add_flag("--welch", a.welch, "Welch averaging even when the force looks like hammer hits")
      ->excludes(impact);
  cmd->add_option("--window", a.window,
                  "Welch window: rect, hann, hamming, blackmanharris, flattop")
      ->capture_default_str();
  cmd->add_option("--segment", a.segment,
                  "Welch segment length in samples (default: a power of two, at most 4096 and a "
                  "quarter of the record)");
  cmd->add_option("--overlap", a.overlap, "Welch overlap in samples (default: half a segment)");
  cmd->add_option("--detrend", a.detrend, "Welch per-segment detrend: none, constant")
      ->capture_default_str();
  cmd->add_option("--sensor", a.sensor,
                  "What the response channels measure: acc, vel or disp, for all or one per "
                  "response (acc,acc,disp); default: each as its unit says (acc1_m_s2, x1_m, "
                  "COLUMN:mm), acceleration when it says none");
  cmd->add_option("--kind", a.kind, "FRF to produce: receptance, mobility, accelerance")
      ->capture_default_str();
  cmd->add_option("--fs-hz", a.fs_hz, "Sample rate (Hz) when the recording has no t_s column")
      ->check(PositiveNumber());
  cmd->add_option("--trigger", a.impact_options.trigger_fraction,
                  "Impact: hit threshold as a fraction of the largest force")
      ->capture_default_str();
  cmd->add_option("--pretrigger-s", a.impact_options.pretrigger_s,
                  "Impact: seconds kept before each hit (default: 1/64 of the hit record)");
  cmd->add_option("--record-s", a.impact_options.record_s,
                  "Impact: length of each hit's record, s (default: the shortest hit spacing)")
      ->check(NonNegativeNumber());
  cmd->add_option(
         "--force-window-s", a.impact_options.force_window_s,
         "Impact: force kept up to this time after the trigger, s (default: twice the pulse width)")
      ->check(NonNegativeNumber());
  cmd->add_option("--exp-window", a.impact_options.exp_window_end,
                  "Impact: exponential window on force and responses, its value at the record end "
                  "(0: none); damping is corrected for it")
      ->check(NonNegativeNumber());
  cmd->add_option(
         "--double-hit-window-s", a.impact_options.double_hit_window_s,
         "Impact: pulses closer than this to the previous one are rebounds of the same hit, s")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  cmd->add_flag("--keep-bad-hits", a.keep_bad_hits,
                "Impact: use double, clipped and weak hits (only flag them)");
  cmd->add_option("--weak-hit-fraction", a.impact_options.weak_hit_fraction,
                  "Impact: a hit below this fraction of the median peak of the good hits is too "
                  "weak (0: no check)")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  cmd->add_option("--weak-hit-noise-factor", a.impact_options.weak_hit_noise_factor,
                  "Impact: a hit below this many force-noise standard deviations is too weak "
                  "(0: no check)")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  cmd->add_option("--use-hits", a.use_hits,
                  "Impact: average these hits whatever their verdicts, e.g. 1,2,4 (numbered as "
                  "the hit notes number them)");
  cmd->add_option("--hits", a.hits_file,
                  "Impact: average the accepted hits of a hit list a hammer session saved "
                  "(hits.json)");
}

ident::Frf LoadOrEstimate(const std::string& path, const EstimationArgs& a,
                          std::vector<std::string>& notes) {
  Estimated e = workflow::LoadOrEstimate(path, a);
  // Said on stderr too: a user who did not ask for a processing mode should see which one ran.
  KeepEstimationNotes(path, e, true, notes);
  return std::move(e.frf);
}

void KeepEstimationNotes(const std::string& path, const Estimated& e, bool say_note,
                         std::vector<std::string>& notes) {
  if (say_note && !e.note.empty()) std::cerr << "vibid: note: " << e.note << "\n";
  for (const std::string& w : e.warnings) std::cerr << "vibid: warning: " << w << "\n";
  const std::vector<std::string> lines = workflow::EstimationNotes(path, e);
  notes.insert(notes.end(), lines.begin(), lines.end());
}

}  // namespace vibid::cli
