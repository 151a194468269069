// The library's own time for what the Python package's frf_estimate and modes call, on a
// recording: FRF estimation from signals in memory (workflow::EstimateFromSignals, the columns
// given as one column-major matrix, as numpy's (channels, samples) array reaches it), and `vibid
// modes` on the file (read, estimate, modes, JSON). Best of REPEATS runs each after an untimed one,
// wall time. Used by run_bench.py, which times the Python calls on the same input in the same run.
//   bench_workflow REC.csv [REPEATS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/modes_request.hpp"
#include "vibid/workflow/result_json.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_workflow REC.csv [REPEATS]\n");
    return 2;
  }
  using clock = std::chrono::steady_clock;
  namespace wf = vibid::workflow;
  const std::string path = argv[1];
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  try {
    const vibid::Recording rec = vibid::LoadRecording(path);
    const Eigen::VectorXd force = rec.table.Column("force_n");
    Eigen::MatrixXd responses(static_cast<Eigen::Index>(rec.samples()), 2);
    responses.col(0) = rec.table.Column("acc1_m_s2");
    responses.col(1) = rec.table.Column("acc2_m_s2");
    wf::EstimationOptions options;
    options.force = "force_n";
    options.responses = "acc1_m_s2,acc2_m_s2";
    double estimate_s = 1e300;
    double checksum = 0.0;
    // One untimed run of each first: the Python side times a warm process too (allocations and
    // the spectra's threads already touched).
    for (int r = -1; r < repeats; ++r) {
      const auto t0 = clock::now();
      const wf::Estimated e = wf::EstimateFromSignals(force, responses, rec.fs_hz, "force_n",
                                                      {"acc1_m_s2", "acc2_m_s2"}, options);
      if (r >= 0)
        estimate_s = std::min(estimate_s, std::chrono::duration<double>(clock::now() - t0).count());
      checksum += e.frf.coherence.sum();
    }
    double modes_s = 1e300;
    for (int r = -1; r < repeats; ++r) {
      const auto t0 = clock::now();
      wf::Estimated e = wf::LoadOrEstimate(path, options);
      const std::vector<std::string> notes = wf::EstimationNotes(path, e);
      const vibid::ident::Frf frf = wf::JoinColumns({e.frf}, {path});
      const wf::ModeRequest request;
      const vibid::ident::ModeIdentification m = wf::IdentifyModes(frf, request);
      const std::string json =
          wf::ModeIdentificationJson(m, request.method, frf.response_names, notes).dump();
      if (r >= 0)
        modes_s = std::min(modes_s, std::chrono::duration<double>(clock::now() - t0).count());
      checksum += static_cast<double>(json.size());
    }
    std::printf("samples %zu estimate_s %.5f modes_s %.5f checksum %.12g\n", rec.samples(),
                estimate_s, modes_s, checksum);
  } catch (const vibid::InputError& e) {
    std::fprintf(stderr, "bench_workflow: %s\n", e.what());
    return 1;
  }
  return 0;
}
