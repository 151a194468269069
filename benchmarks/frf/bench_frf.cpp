// Times H1 + coherence (Welch: Hann, 50 % overlap) on a recording: reading the CSV and the spectral
// estimation separately, best of several runs for the estimation; wall time and process CPU time
// (all threads). Used by run_bench.py.
//   bench_frf REC.csv SEGMENT [REPEATS]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/spectral.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_frf REC.csv SEGMENT [REPEATS]\n");
    return 2;
  }
  using clock = std::chrono::steady_clock;
  const std::string path = argv[1];
  const auto segment = static_cast<std::size_t>(std::strtoul(argv[2], nullptr, 10));
  const int repeats = argc > 3 ? std::atoi(argv[3]) : 3;
  try {
    const auto t0 = clock::now();
    const std::clock_t c0 = std::clock();  // process CPU time, all threads
    const vibid::Recording rec = vibid::LoadRecording(path);
    // As frf-estimate reads them: unscaled channels are the recording's own columns.
    const Eigen::VectorXd& force = rec.table.Column("force_n");
    const std::vector<const Eigen::VectorXd*> resp = {&rec.table.Column("acc1_m_s2"),
                                                      &rec.table.Column("acc2_m_s2")};
    const double load_s = std::chrono::duration<double>(clock::now() - t0).count();
    const double load_cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    double best = 1e300;
    double best_cpu = 1e300;
    double checksum = 0.0;
    for (int r = 0; r < repeats; ++r) {
      const auto t1 = clock::now();
      const std::clock_t c1 = std::clock();
      const vibid::ident::CrossSpectra s = vibid::ident::WelchSpectra(
          force, resp, rec.fs_hz, {.segment_samples = segment, .overlap_samples = segment / 2});
      const vibid::ident::Frf frf = vibid::ident::FrfFromSpectra(
          s, vibid::ident::Estimator::kH1, vibid::ident::Quantity::kAcceleration);
      best = std::min(best, std::chrono::duration<double>(clock::now() - t1).count());
      best_cpu = std::min(best_cpu, static_cast<double>(std::clock() - c1) / CLOCKS_PER_SEC);
      checksum = frf.coherence.sum() + std::abs(frf.h(frf.h.rows() / 3, 0));
    }
    std::printf(
        "samples %zu segment %zu load_s %.4f compute_s %.4f load_cpu_s %.4f compute_cpu_s %.4f "
        "checksum %.12g\n",
        rec.samples(), segment, load_s, best, load_cpu_s, best_cpu, checksum);
  } catch (const vibid::InputError& e) {
    std::fprintf(stderr, "bench_frf: %s\n", e.what());
    return 1;
  }
  return 0;
}
