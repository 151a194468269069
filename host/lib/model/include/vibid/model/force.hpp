// Force inputs for time simulation: standard shapes and tables.
//
// Shape SPEC strings (the CLI's --force), `KIND:key=value,...`, dof counted from 1, SI units:
//   step:dof=1,amp=5[,t0=0]                      amp (N) for t ≥ t0
//   pulse:dof=1,amp=5,width=0.1[,t0=0]           amp for t0 ≤ t < t0 + width
//   halfsine:dof=2,amp=100,width=0.001[,t0=0]    amp sin(π (t − t0)/width) on [t0, t0 + width]
//   (hammer) sine:dof=2,amp=1,freq_hz=16[,t0=0]           amp sin(2π f (t − t0)) for t ≥ t0
//   chirp:dof=1,amp=1,f0_hz=1,f1_hz=50,t1=10[,t0=0]
//                                                linear sweep f0 → f1 over t1 seconds from t0,
//                                                amp sin(2π (f0 τ + (f1 − f0) τ²/(2 t1))), τ = t −
//                                                t0; zero outside [t0, t0 + t1]
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace vibid::model {

enum class ShapeKind { kStep, kPulse, kHalfSine, kSine, kChirp };

struct ForceShape {
  ShapeKind kind = ShapeKind::kStep;
  int dof = 0;  ///< 0-based
  double amp_n = 0.0;
  double t0_s = 0.0;
  double width_s = 0.0;  ///< pulse, halfsine
  double freq_hz = 0.0;  ///< sine
  double f0_hz = 0.0;    ///< chirp start
  double f1_hz = 0.0;    ///< chirp end
  double t1_s = 0.0;     ///< chirp duration
};

/// Parses a SPEC (see above). InputError naming the spec and the bad or missing key.
ForceShape ParseForceShape(std::string_view spec);

/// Which side of a discontinuity (a pulse edge, a table sample) an instant refers to. Shapes and
/// tables are right-continuous: a sample at t sees kFrom. An integration step ending at t needs the
/// value just before (kBefore), so that a pulse ending on a step boundary is not cut short.
/// Instants within 1e-12 (relative, at least 1e-12 s) of an edge count as on it.
enum class Side { kFrom, kBefore };

/// Value of the shape at time t_s, N.
double EvaluateShape(const ForceShape& shape, double t_s, Side side = Side::kFrom);

/// Sampled forces, zero-order held: the row with the latest t_s ≤ t applies; zero before the first.
struct ForceTable {
  Eigen::VectorXd t_s;      ///< strictly increasing
  Eigen::MatrixXd force_n;  ///< rows = samples, columns = DOFs
};

/// Reads a CSV with a `t_s` column and `f<dof>_n` columns (dof from 1; missing ones are zero).
ForceTable LoadForceTable(const std::string& path, int dofs);

/// Everything that pushes on the model: the sum of the shapes and the table (either may be empty).
struct ForceInput {
  std::vector<ForceShape> shapes;
  ForceTable table;

  bool empty() const { return shapes.empty() && table.t_s.size() == 0; }
};

/// InputError unless every shape and the table fit a model with `dofs` DOFs and are finite.
void ValidateForceInput(const ForceInput& input, int dofs, const std::string& what = "force");

/// Writes the force on each DOF at t_s into `out` (size dofs). No allocation.
void EvaluateForce(const ForceInput& input, double t_s, Eigen::Ref<Eigen::VectorXd> out,
                   Side side = Side::kFrom);

}  // namespace vibid::model
