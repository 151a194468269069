// Host speed of the fixed-point observer kernel (the code the board runs and the host replays):
// ns per sample for the default design (2 inputs, 4 + 3 sections), per-sample Step and StepBlock.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "vibid/dob/chain_plant.hpp"
#include "vibid/dob/design.hpp"
#include "vibid/shared/fixed/dob_filter.hpp"

namespace {

using namespace vibid;

const fixed::FilterDescription& DefaultDescription() {
  static const dob::DobDesign design =
      dob::DesignObserver(dob::ChainPlantForceOnM2({}), dob::DobOptions{});
  return design.fixed.description;
}

std::vector<std::int32_t> Inputs(std::size_t frames) {
  std::vector<std::int32_t> in(2 * frames);
  std::uint32_t lcg = 1;
  for (auto& v : in) {
    lcg = lcg * 1664525u + 1013904223u;
    v = static_cast<std::int32_t>(lcg) >> 4;  // 1/16 of full scale
  }
  return in;
}

void BM_DobStepBlock(benchmark::State& state) {
  const auto frames = static_cast<std::size_t>(state.range(0));
  const std::vector<std::int32_t> in = Inputs(frames);
  std::vector<std::int32_t> out(frames);
  fixed::DobFilter filter;
  if (filter.Init(DefaultDescription()) != Status::kOk) state.SkipWithError("description refused");
  for (auto _ : state) {
    benchmark::DoNotOptimize(filter.StepBlock(in, out));
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_DobStepBlock)->Arg(256)->Arg(4096);

void BM_DobStep(benchmark::State& state) {
  const std::vector<std::int32_t> in = Inputs(4096);
  fixed::DobFilter filter;
  if (filter.Init(DefaultDescription()) != Status::kOk) state.SkipWithError("description refused");
  std::size_t k = 0;
  for (auto _ : state) {
    const fixed::InputFrame frame{in[2 * k], in[2 * k + 1], 0};
    benchmark::DoNotOptimize(filter.Step(frame));
    k = (k + 1) % 4096;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_DobStep);

}  // namespace

BENCHMARK_MAIN();
