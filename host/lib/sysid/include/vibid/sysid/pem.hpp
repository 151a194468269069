// Prediction-error estimation of ARMAX, OE and Box–Jenkins models (and ARX, which is solved by
// linear least squares).
//
// The mean squared one-step prediction error V = (1/N) Σ e(t)², e = D/C (A y − B/F u), zero initial
// conditions, is minimised by Levenberg–Marquardt with the analytic gradient: every column of
// ∂e/∂θ is a filtered, delayed copy of y, u, e, A y − B/F u or B/F u (Ljung, System Identification,
// 2nd ed., §10.2). Starting points: ARX for ARMAX (Hannan–Rissanen for C), a refined
// instrumental-variable estimate for OE, and OE + Hannan–Rissanen on the output error for
// Box–Jenkins.
#pragma once

#include <string>

#include "vibid/numerics/least_squares.hpp"
#include "vibid/sysid/io_data.hpp"
#include "vibid/sysid/poly_model.hpp"

namespace vibid::sysid {

struct PemResult {
  PolyModel model;
  numerics::SolverSummary summary;
  std::string
      initialization;  ///< How the start was found ("least-squares", "instrumental-variable", ...).
};

/// Estimates the model. InputError on orders that do not fit the structure or the record.
/// Numerical trouble (no convergence) is reported in the summary; the model then holds the last
/// accepted parameters.
PemResult EstimatePem(const IoData& data, Structure structure, const PolyOrders& orders,
                      const numerics::SolverOptions& options = {});

/// Instrumental-variable estimate of an OE model B/F (orders nb, nf, nk): the basic IV (delayed
/// inputs as instruments; ARX when it has no solution), then up to 20 passes of the simplified
/// refined IV method (data prefiltered by 1/F̂, the current model's noise-free output as
/// instruments), ended when the relative parameter change falls below `tolerance`. The regressions
/// are written in backward differences (the δ-operator basis) so that they stay well conditioned at
/// high sample rates. On records of at least 2000 (nb + nf) samples the first passes run on the
/// first quarter, and the passes on the whole record continue from there. F is stabilised.
PolyModel EstimateOeIv(const IoData& data, const PolyOrders& orders, double tolerance = 1e-9);

}  // namespace vibid::sysid
