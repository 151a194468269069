// Time simulation of the nominal 2-DOF rig: 60 s at 5 kHz (300 001 samples) per iteration.
#include <benchmark/benchmark.h>

#include "vibid/model/simulate.hpp"

namespace vibid::model {
namespace {

Model Rig() {
  return MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                   Eigen::Vector2d(2.0, 1.5));
}

void BM_Simulate(benchmark::State& state) {
  SimulationOptions o;
  o.method = static_cast<Method>(state.range(0));
  o.dt_s = 1.0 / 5000.0;
  o.t_end_s = 60.0;
  if (state.range(1) != 0) o.friction = {{0.02, 0.015}};
  ForceInput force;
  force.shapes.push_back(ParseForceShape("chirp:dof=1,amp=5,f0_hz=1,f1_hz=50,t1=60"));
  force.shapes.push_back(ParseForceShape("halfsine:dof=2,amp=100,t0=0.5,width=0.001"));
  for (auto _ : state) {
    const SimulationResult r = Simulate(Rig(), force, o);
    benchmark::DoNotOptimize(r.x_m.data());
  }
  state.SetItemsProcessed(state.iterations() * 300001);
  state.SetLabel(std::string(MethodName(o.method)) + (state.range(1) != 0 ? "+friction" : ""));
}
BENCHMARK(BM_Simulate)
    ->Args({static_cast<int>(Method::kExact), 0})
    ->Args({static_cast<int>(Method::kRk4), 0})
    ->Args({static_cast<int>(Method::kEuler), 0})
    ->Args({static_cast<int>(Method::kRk4), 1})
    ->Unit(benchmark::kMillisecond);

void BM_SimulatorStep(benchmark::State& state) {
  SimulationOptions o;
  o.method = Method::kExact;
  o.dt_s = 1.0 / 5000.0;
  Simulator sim(Rig(), o);
  const Eigen::Vector2d force(1.0, 0.0);
  for (auto _ : state) {
    sim.Step(force);
    benchmark::DoNotOptimize(sim.position_m().data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimulatorStep);

}  // namespace
}  // namespace vibid::model
