#include "vibid/model/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/LU>

#include "number_text.hpp"
#include "vibid/common/enum_names.hpp"
#include "vibid/common/error.hpp"
#include "vibid/model/state_space.hpp"

namespace vibid::model {
namespace {

// Beyond this many stored values a simulation is a typo in --t-end-s, not a request.
constexpr double kMaxStoredValues = 2e8;

Eigen::Index SampleCount(const SimulationOptions& options) {
  return static_cast<Eigen::Index>(std::floor(options.t_end_s / options.dt_s + 1e-9)) + 1;
}

constexpr EnumNames<Method, 3> kMethodNames{
    {{Method::kEuler, "euler"}, {Method::kRk4, "rk4"}, {Method::kExact, "exact"}}};

}  // namespace

Method ParseMethod(std::string_view name) {
  return ParseName(kMethodNames, name, "simulation method");
}

std::string_view MethodName(Method method) { return NameOf(kMethodNames, method, "rk4"); }

void ValidateOptions(const Model& model, const SimulationOptions& options) {
  Validate(model);
  const Eigen::Index n = model.m_kg.rows();
  Require(options.method == Method::kEuler || options.method == Method::kRk4 ||
              options.method == Method::kExact,
          "unknown simulation method");
  Require(std::isfinite(options.dt_s) && options.dt_s > 0.0,
          "dt_s must be finite and > 0, got " + detail::NumberText(options.dt_s));
  Require(std::isfinite(options.t_end_s) && options.t_end_s > options.dt_s,
          "t_end_s must be finite and greater than dt_s (" + detail::NumberText(options.dt_s) +
              " s), got " + detail::NumberText(options.t_end_s));
  Require(options.x0_m.size() == 0 || options.x0_m.size() == n,
          "x0 has " + std::to_string(options.x0_m.size()) + " entries, the model has " +
              std::to_string(n) + " DOFs");
  Require(options.v0_m_s.size() == 0 || options.v0_m_s.size() == n,
          "v0 has " + std::to_string(options.v0_m_s.size()) + " entries, the model has " +
              std::to_string(n) + " DOFs");
  Require(options.x0_m.allFinite() && options.v0_m_s.allFinite(), "initial state must be finite");
  const std::size_t nf = options.friction.size();
  Require(nf == 0 || nf == 1 || nf == static_cast<std::size_t>(n),
          "friction needs one entry or one per DOF (" + std::to_string(n) + "), got " +
              std::to_string(nf));
  for (const CoulombFriction& f : options.friction) {
    Require(std::isfinite(f.mu_static) && std::isfinite(f.mu_dynamic) && f.mu_dynamic >= 0.0,
            "friction coefficients must be finite and >= 0");
    Require(f.mu_static >= f.mu_dynamic, "static friction coefficient must be >= the dynamic one");
  }
  if (nf > 0) {
    Require(options.method != Method::kExact,
            "the exact (zero-order-hold) method is linear and cannot simulate Coulomb friction; "
            "use rk4 or euler");
    const Eigen::MatrixXd off = model.m_kg - Eigen::MatrixXd(model.m_kg.diagonal().asDiagonal());
    Require(off.cwiseAbs().maxCoeff() == 0.0,
            "Coulomb friction needs a diagonal mass matrix (one mass per DOF)");
    Require(std::isfinite(options.gravity_m_s2) && options.gravity_m_s2 > 0.0,
            "gravity must be finite and > 0");
  }
}

// The integrator shared by Simulate and Simulator.
class SimulationEngine {
 public:
  int n = 0;
  Method method = Method::kRk4;
  double dt = 0.0;
  Eigen::MatrixXd m_inv, k, c;
  Eigen::MatrixXd ad, bd;  // exact method
  // Coulomb friction: thresholds in N (static, dynamic), direction of motion during a sub-step.
  bool has_friction = false;
  Eigen::VectorXd static_n, dynamic_n, direction;
  std::vector<bool> stuck;

  double t = 0.0;
  Eigen::VectorXd x, v, a, f_last;
  // Scratch, sized once.
  Eigen::VectorXd f, r, z, z_next, x0, v0, xs, vs, k1x, k1v, k2x, k2v, k3x, k3v, k4x, k4v;

  SimulationEngine(const Model& model, const SimulationOptions& options) {
    ValidateOptions(model, options);
    n = model.dofs();
    method = options.method;
    dt = options.dt_s;
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(model.m_kg);
    m_inv = lu.inverse();
    k = model.k_n_per_m;
    c = model.c_ns_per_m;
    if (method == Method::kExact) {
      const StateSpace d = Discretize(ModelStateSpace(model), dt);
      ad = d.A;
      bd = d.B;
    }
    const auto un = static_cast<Eigen::Index>(n);
    for (Eigen::VectorXd* vec :
         {&x,   &v,   &a,   &f_last, &f,   &r,   &x0,  &v0,       &xs,        &vs,       &k1x,
          &k1v, &k2x, &k2v, &k3x,    &k3v, &k4x, &k4v, &static_n, &dynamic_n, &direction}) {
      *vec = Eigen::VectorXd::Zero(un);
    }
    z = Eigen::VectorXd::Zero(2 * un);
    z_next = Eigen::VectorXd::Zero(2 * un);
    if (options.x0_m.size() == un) x = options.x0_m;
    if (options.v0_m_s.size() == un) v = options.v0_m_s;
    stuck.assign(static_cast<std::size_t>(n), false);
    has_friction = !options.friction.empty();
    for (Eigen::Index i = 0; i < un && has_friction; ++i) {
      const CoulombFriction& cf = options.friction.size() == 1
                                      ? options.friction[0]
                                      : options.friction[static_cast<std::size_t>(i)];
      const double normal_n = model.m_kg(i, i) * options.gravity_m_s2;
      static_n[i] = cf.mu_static * normal_n;
      dynamic_n[i] = cf.mu_dynamic * normal_n;
      // A mass with friction that starts at rest starts held; the static test decides on release.
      stuck[static_cast<std::size_t>(i)] = HasFriction(i) && v[i] == 0.0;
    }
  }

  bool HasFriction(Eigen::Index i) const {
    return has_friction && (static_n[i] > 0.0 || dynamic_n[i] > 0.0);
  }

  // Net force on each mass from the inputs, springs and dampers (friction excluded) → r.
  void NetForce(const Eigen::VectorXd& xq, const Eigen::VectorXd& vq) {
    r = f;
    r.noalias() -= k * xq;
    r.noalias() -= c * vq;
  }

  // Acceleration at (xq, vq) with the force currently in `f` and the current stick/slip state.
  void Acceleration(const Eigen::VectorXd& xq, const Eigen::VectorXd& vq, Eigen::VectorXd& out) {
    NetForce(xq, vq);
    if (has_friction) {
      for (Eigen::Index i = 0; i < n; ++i) {
        if (HasFriction(i) && !stuck[static_cast<std::size_t>(i)])
          r[i] -= dynamic_n[i] * direction[i];
      }
    }
    out.noalias() = m_inv * r;
    if (has_friction) {
      for (Eigen::Index i = 0; i < n; ++i) {
        if (stuck[static_cast<std::size_t>(i)]) out[i] = 0.0;
      }
    }
  }

  // Static test for held masses and the friction direction of moving ones, at the current state.
  template <typename ForceFn>
  void UpdateStick(ForceFn& force_at) {
    if (!has_friction) return;
    force_at(t, f, Side::kFrom);
    NetForce(x, v);
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!HasFriction(i)) continue;
      const auto si = static_cast<std::size_t>(i);
      if (v[i] != 0.0) {
        stuck[si] = false;
        direction[i] = v[i] > 0.0 ? 1.0 : -1.0;
      } else if (std::abs(r[i]) > static_n[i]) {
        stuck[si] = false;
        direction[i] = r[i] > 0.0 ? 1.0 : -1.0;
      } else {
        stuck[si] = true;
      }
    }
  }

  template <typename ForceFn>
  void Integrate(ForceFn& force_at, double h) {
    if (method == Method::kEuler) {
      force_at(t, f, Side::kFrom);
      Acceleration(x, v, k1v);
      x.noalias() += h * v;
      v.noalias() += h * k1v;
      return;
    }
    // Classical RK4 on (x, v), forces at the stage times; the last stage takes the value just
    // before t + h, the end of the interval this step integrates over.
    force_at(t, f, Side::kFrom);
    Acceleration(x, v, k1v);
    k1x = v;
    force_at(t + 0.5 * h, f, Side::kFrom);
    xs = x + 0.5 * h * k1x;
    vs = v + 0.5 * h * k1v;
    Acceleration(xs, vs, k2v);
    k2x = vs;
    xs = x + 0.5 * h * k2x;
    vs = v + 0.5 * h * k2v;
    Acceleration(xs, vs, k3v);
    k3x = vs;
    force_at(t + h, f, Side::kBefore);
    xs = x + h * k3x;
    vs = v + h * k3v;
    Acceleration(xs, vs, k4v);
    k4x = vs;
    x.noalias() += (h / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    v.noalias() += (h / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
  }

  // One step of dt. With friction the step is split where a sliding mass stops.
  template <typename ForceFn>
  void Advance(ForceFn& force_at) {
    const double t_start = t;
    if (method == Method::kExact) {
      force_at(t, f, Side::kFrom);
      z.head(n) = x;
      z.tail(n) = v;
      z_next.noalias() = ad * z;
      z_next.noalias() += bd * f;
      x = z_next.head(n);
      v = z_next.tail(n);
      t = t_start + dt;
      return;
    }
    if (!has_friction) {
      Integrate(force_at, dt);
      t = t_start + dt;
      return;
    }
    double remaining = dt;
    // Each split stops one more mass; 2n + 2 splits cover every mass stopping twice in a step.
    for (int split = 0; split < 2 * n + 2 && remaining > 1e-12 * dt; ++split) {
      UpdateStick(force_at);
      x0 = x;
      v0 = v;
      Integrate(force_at, remaining);
      double fraction = 1.0;
      Eigen::Index first = -1;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (!HasFriction(i) || stuck[static_cast<std::size_t>(i)]) continue;
        const double before = direction[i] * v0[i];  // ≥ 0: speed along the friction direction
        const double after = direction[i] * v[i];
        if (after < 0.0) {
          const double crossing = before / (before - after);
          if (crossing < fraction) {
            fraction = crossing;
            first = i;
          }
        }
      }
      if (first < 0) {
        t += remaining;
        remaining = 0.0;
        break;
      }
      // Redo the sub-step up to the (linearly interpolated) instant the first mass stops.
      const double h = fraction * remaining;
      x = x0;
      v = v0;
      if (h > 0.0) Integrate(force_at, h);
      v[first] = 0.0;
      stuck[static_cast<std::size_t>(first)] = true;
      t += h;
      remaining -= h;
    }
    if (remaining > 1e-12 * dt) {
      // Out of splits (a mass chattering at the static limit): finish the step and stop any mass
      // whose velocity turned against its friction.
      UpdateStick(force_at);
      Integrate(force_at, remaining);
      for (Eigen::Index i = 0; i < n; ++i) {
        if (HasFriction(i) && !stuck[static_cast<std::size_t>(i)] && direction[i] * v[i] < 0.0) {
          v[i] = 0.0;
          stuck[static_cast<std::size_t>(i)] = true;
        }
      }
    }
    t = t_start + dt;
  }

  template <typename ForceFn>
  void UpdateAcceleration(ForceFn& force_at) {
    UpdateStick(force_at);
    force_at(t, f, Side::kFrom);
    f_last = f;
    Acceleration(x, v, a);
  }
};

struct Simulator::Impl : SimulationEngine {
  using SimulationEngine::SimulationEngine;
};

Simulator::Simulator(const Model& model, const SimulationOptions& options)
    : impl_(std::make_unique<Impl>(model, options)) {}
Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

void Simulator::Step(Eigen::Ref<const Eigen::VectorXd> force_n) {
  Require(force_n.size() == impl_->n, "force vector has " + std::to_string(force_n.size()) +
                                          " entries, the model has " + std::to_string(impl_->n) +
                                          " DOFs");
  auto held = [&force_n](double, Eigen::VectorXd& out, Side) { out = force_n; };
  impl_->Advance(held);
  impl_->UpdateAcceleration(held);
}

double Simulator::time_s() const { return impl_->t; }
const Eigen::VectorXd& Simulator::position_m() const { return impl_->x; }
const Eigen::VectorXd& Simulator::velocity_m_s() const { return impl_->v; }
const Eigen::VectorXd& Simulator::acceleration_m_s2() const { return impl_->a; }
const std::vector<bool>& Simulator::stuck() const { return impl_->stuck; }

SimulationResult Simulate(const Model& model, const ForceInput& force,
                          const SimulationOptions& options) {
  return Simulate(model, force, ForceInput{}, options);
}

SimulationResult Simulate(const Model& model, const ForceInput& force,
                          const ForceInput& disturbance, const SimulationOptions& options) {
  ValidateOptions(model, options);
  const int n = model.dofs();
  ValidateForceInput(force, n, "force");
  ValidateForceInput(disturbance, n, "disturbance");
  const Eigen::Index samples = SampleCount(options);
  Require(static_cast<double>(samples) * 5.0 * n <= kMaxStoredValues,
          "simulation would store " + std::to_string(samples) +
              " samples; raise dt_s or lower t_end_s");

  SimulationEngine sim(model, options);
  Eigen::VectorXd force_now = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd disturbance_now = Eigen::VectorXd::Zero(n);
  const bool has_disturbance = !disturbance.empty();
  auto total = [&](double t_s, Eigen::VectorXd& out, Side side) {
    EvaluateForce(force, t_s, out, side);
    if (has_disturbance) {
      EvaluateForce(disturbance, t_s, disturbance_now, side);
      out += disturbance_now;
    }
  };

  SimulationResult result;
  result.t_s.resize(samples);
  for (Eigen::MatrixXd* m :
       {&result.x_m, &result.v_m_s, &result.a_m_s2, &result.force_n, &result.disturbance_n}) {
    m->resize(samples, n);
  }
  for (Eigen::Index k = 0; k < samples; ++k) {
    if (k > 0) {
      sim.Advance(total);
      sim.t = static_cast<double>(k) * options.dt_s;  // no accumulated rounding in the time base
    }
    sim.UpdateAcceleration(total);
    result.t_s[k] = sim.t;
    result.x_m.row(k) = sim.x.transpose();
    result.v_m_s.row(k) = sim.v.transpose();
    result.a_m_s2.row(k) = sim.a.transpose();
    EvaluateForce(force, sim.t, force_now);
    result.force_n.row(k) = force_now.transpose();
    if (has_disturbance) {
      EvaluateForce(disturbance, sim.t, disturbance_now);
      result.disturbance_n.row(k) = disturbance_now.transpose();
    } else {
      result.disturbance_n.row(k).setZero();
    }
  }
  return result;
}

}  // namespace vibid::model
