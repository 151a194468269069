// SSI-cov (output-only modes with their intervals) of 10 minutes of 4 channels at 1 kHz: a
// four-mass chain under white forces on every mass, accelerations with 1 % noise. The counter
// realtime_ratio is the record's duration over the analysis time (the watch needs >= 100).
// And one block of `vibid watch` at its defaults (below).
//
//   build/host/benchmarks/oma/oma_bench
#include <benchmark/benchmark.h>

#include <ctime>

#include "vibid/model/model.hpp"
#include "vibid/oma/ssi_cov.hpp"
#include "vibid/oma/testing/ambient.hpp"
#include "vibid/oma/testing/textbook_intervals.hpp"

namespace {

constexpr double kSeconds = 600.0;

const Eigen::MatrixXd& Record() {
  static const Eigen::MatrixXd y = [] {
    const vibid::model::Model rig = vibid::model::MakeChain(
        Eigen::Vector4d(1.8, 1.5, 1.2, 1.0), Eigen::Vector4d(3500.0, 2800.0, 2200.0, 1600.0),
        Eigen::Vector4d(4.0, 3.0, 2.5, 2.0));
    vibid::oma::testing::AmbientOptions sim;
    sim.fs_hz = 1000.0;
    sim.seconds = kSeconds;
    return vibid::oma::testing::SimulateAmbient(rig, sim);
  }();
  return y;
}

void BM_SsiCov10MinFourChannels(benchmark::State& state) {
  const Eigen::MatrixXd& y = Record();
  vibid::oma::SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 30.0;
  std::size_t modes = 0;
  for (auto _ : state) {
    const vibid::oma::SsiCovResult r = vibid::oma::SsiCov(y, o);
    modes = r.modes.size();
    benchmark::DoNotOptimize(modes);
  }
  state.counters["modes"] = static_cast<double>(modes);
  state.counters["realtime_ratio"] = benchmark::Counter(
      kSeconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SsiCov10MinFourChannels)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// One block of `vibid watch` at its defaults: the modes over the last 120 s (modes_s) of two
// accelerations at 1 kHz (the board's default rate), band 25 Hz, with their intervals from 200
// samples of the Hankel covariance, recomputed every 10 s block. Counters: the process's CPU per
// block (std::clock) and that as a share of one core for a rig (CPU / 10 s); the watch's target
// is at most 1 % (100 ms per block).
//
//   build/host/benchmarks/oma/oma_bench --benchmark_filter=Watch
const Eigen::MatrixXd& WatchRecord() {
  static const Eigen::MatrixXd y = [] {
    // The emulator's default rig truth (host/emulator/rigs/default.json), as the watch's tests.
    const vibid::model::Model rig = vibid::model::MakeChain(
        Eigen::Vector2d(1.82, 1.53), Eigen::Vector2d(3520.0, 2760.0), Eigen::Vector2d(5.0, 3.5));
    vibid::oma::testing::AmbientOptions sim;
    sim.fs_hz = 1000.0;
    sim.seconds = 120.0;
    return vibid::oma::testing::SimulateAmbient(rig, sim);
  }();
  return y;
}

constexpr double kWatchBlockS = 10.0;

void BM_WatchBlockModes(benchmark::State& state) {
  const Eigen::MatrixXd& y = WatchRecord();
  vibid::oma::SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 25.0;
  o.draws = static_cast<int>(state.range(0));
  std::size_t modes = 0;
  double cpu_s = 0.0;
  for (auto _ : state) {
    const std::clock_t start = std::clock();
    const vibid::oma::SsiCovResult r = vibid::oma::SsiCov(y, o);
    cpu_s += static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    modes = r.modes.size();
    benchmark::DoNotOptimize(modes);
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["modes"] = static_cast<double>(modes);
  state.counters["cpu_ms_per_block"] = 1000.0 * cpu_s / n;
  state.counters["core_percent_per_rig"] = 100.0 * cpu_s / n / kWatchBlockS;
}
BENCHMARK(BM_WatchBlockModes)->Arg(200)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The peer in the same run: the same block's 200 interval samples propagated the textbook way
// (an SVD and the full eigensolver per sample and mode order; testing::TextbookIntervals, the
// reference the intervals are tested against), the mean fit not counted. Counter as above.
void BM_WatchBlockTextbookIntervals(benchmark::State& state) {
  const Eigen::MatrixXd& y = WatchRecord();
  vibid::oma::SsiCovOptions o;
  o.fs_hz = 1000.0;
  o.fmax_hz = 25.0;
  o.draws = static_cast<int>(state.range(0));
  const vibid::oma::SsiCovResult fit = vibid::oma::SsiCov(y, o);
  double cpu_s = 0.0;
  for (auto _ : state) {
    const std::clock_t start = std::clock();
    const auto intervals = vibid::oma::testing::TextbookIntervals(y, o, fit);
    cpu_s += static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    benchmark::DoNotOptimize(intervals.data());
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["cpu_ms_per_block"] = 1000.0 * cpu_s / n;
  state.counters["core_percent_per_rig"] = 100.0 * cpu_s / n / kWatchBlockS;
}
BENCHMARK(BM_WatchBlockTextbookIntervals)->Arg(200)->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
