// SSI-cov (output-only modes with their intervals) of 10 minutes of 4 channels at 1 kHz: a
// four-mass chain under white forces on every mass, accelerations with 1 % noise. The counter
// realtime_ratio is the record's duration over the analysis time (the watch needs >= 100).
//
//   build/host/benchmarks/oma/oma_bench
#include <benchmark/benchmark.h>

#include "vibid/model/model.hpp"
#include "vibid/oma/ssi_cov.hpp"
#include "vibid/oma/testing/ambient.hpp"

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

}  // namespace

BENCHMARK_MAIN();
