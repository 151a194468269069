// Time simulation of M ẍ + C ẋ + K x = F(t) + d(t) − f_coulomb (methods §10).
//
// Methods:
//   euler  explicit Euler on the first-order system, forces evaluated at the step start;
//   rk4    classical 4th-order Runge–Kutta, forces evaluated at the stage times (tables: held);
//   exact  zero-order-hold discretisation (state_space.hpp): exact when the force is constant
//          over each step (force sampled at the step start). Linear only: refused (InputError)
//          when Coulomb friction is set — use rk4 or euler.
//
// Coulomb friction (optional, per mass, needs a diagonal M): normal force N_i = m_i g. A mass at
// rest stays at rest while the net non-friction force on it is at most μs N_i; otherwise it
// slides against a friction of μd N_i. A sliding mass whose velocity reaches zero inside a step is
// stopped exactly there (the step is split at the linearly interpolated zero crossing) and the
// static test is applied again.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "vibid/model/force.hpp"
#include "vibid/model/model.hpp"

namespace vibid::model {

enum class Method { kEuler, kRk4, kExact };

/// "euler" | "rk4" | "exact"; InputError otherwise.
Method ParseMethod(std::string_view name);
std::string_view MethodName(Method method);

inline constexpr double kStandardGravity_m_s2 = 9.80665;

struct CoulombFriction {
  double mu_static = 0.0;   ///< ≥ mu_dynamic
  double mu_dynamic = 0.0;  ///< ≥ 0
};

struct SimulationOptions {
  Method method = Method::kRk4;
  double dt_s = 1e-3;    ///< > 0
  double t_end_s = 1.0;  ///< > dt_s; samples at 0, dt, …, up to t_end (inclusive within 1e-9 dt)
  /// Empty: no friction; one entry applies to every mass; otherwise one per DOF.
  std::vector<CoulombFriction> friction;
  double gravity_m_s2 = kStandardGravity_m_s2;
  Eigen::VectorXd x0_m;    ///< Initial positions (empty: zeros).
  Eigen::VectorXd v0_m_s;  ///< Initial velocities (empty: zeros).
};

/// InputError naming the option unless the options fit the model (dt > 0, t_end > dt, sizes,
/// friction coefficients, diagonal M with friction, no friction with exact).
void ValidateOptions(const Model& model, const SimulationOptions& options);

/// Samples at t_s(k) = k dt; matrices have one row per sample and one column per DOF.
struct SimulationResult {
  Eigen::VectorXd t_s;
  Eigen::MatrixXd x_m;
  Eigen::MatrixXd v_m_s;
  Eigen::MatrixXd a_m_s2;         ///< From the equation of motion at each sample.
  Eigen::MatrixXd force_n;        ///< F(t_k)
  Eigen::MatrixXd disturbance_n;  ///< d(t_k)
};

/// Validates model, options and inputs up front (InputError), then simulates.
SimulationResult Simulate(const Model& model, const ForceInput& force,
                          const SimulationOptions& options);
SimulationResult Simulate(const Model& model, const ForceInput& force,
                          const ForceInput& disturbance, const SimulationOptions& options);

/// Step-by-step simulation for callers that produce the force as they go (an emulated rig):
/// each Step holds the given force constant over dt_s. Discrete matrices are precomputed; a Step
/// does not allocate.
class Simulator {
 public:
  /// Validates (t_end_s is not used).
  Simulator(const Model& model, const SimulationOptions& options);
  ~Simulator();
  Simulator(Simulator&&) noexcept;
  Simulator& operator=(Simulator&&) noexcept;
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// Advances one dt_s with `force_n` (size n, F + d) held over the step.
  void Step(Eigen::Ref<const Eigen::VectorXd> force_n);

  double time_s() const;
  const Eigen::VectorXd& position_m() const;
  const Eigen::VectorXd& velocity_m_s() const;
  /// Acceleration at the current state under the last applied force.
  const Eigen::VectorXd& acceleration_m_s2() const;
  /// Which masses are held by static friction (all false without friction).
  const std::vector<bool>& stuck() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vibid::model
