#include "sysid/sysid_cli.hpp"

#include <cmath>
#include <cstdio>

#include "cli_support.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"

namespace vibid::cli {

void AddRecordOptions(CLI::App& cmd, RecordArgs& args) {
  cmd.add_option("recording", args.path, "Recording (CSV with a header; t_s column or --fs-hz)")
      ->required();
  cmd.add_option("--input", args.input,
                 "Input column, e.g. V_volt or I_amp*-178.57 (NAME, NAME:UNIT, NAME*FACTOR)")
      ->required();
  cmd.add_option("--output", args.output, "Output column, e.g. X_encoder_counts*1.7857e-5")
      ->required();
  cmd.add_option("--fs-hz", args.fs_hz, "Sample rate, Hz, for records without a t_s column")
      ->check(PositiveNumber());
  cmd.add_option("--detrend", args.detrend, "Remove none|mean|linear trend from input and output")
      ->check(CLI::IsMember({"none", "mean", "linear"}));
  cmd.add_option("--decimate", args.decimate,
                 "Keep every N-th sample after an anti-alias FIR low-pass")
      ->check(CLI::Range(1, 1000));
}

void Emit(const nlohmann::json& j, const std::string& text, bool json,
          const std::string& out_path) {
  if (!out_path.empty()) EmitOutput(j.dump(2) + "\n", out_path);
  EmitOutput(json ? j.dump(2) + "\n" : text, "");
}

}  // namespace vibid::cli
