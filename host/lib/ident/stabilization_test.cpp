// pLSCF and LSCE poles and the stabilization diagram: against the independent numpy reference of
// scripts/golden/ident_plscf.py, against the exact poles of a digital system, and the automatic
// pole choice on a closed-form 2-DOF FRF.
#include "vibid/ident/stabilization.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"

namespace vibid::ident {
namespace {

using cd = std::complex<double>;

std::string TestData(const std::string& name) {
  return std::string(VIBID_SOURCE_DIR) + "/host/lib/ident/testdata/" + name;
}

// Reference: scripts/golden/ident_plscf.py (numpy, explicit Jacobian blocks, numpy.roots), the
// same FRF file, the same band and order: every pole equal to 1e-6 relative.
TEST(Lscf, PolesMatchTheIndependentNumpyReference) {
  const CsvTable t = ReadCsv(TestData("plscf_frf.csv"));
  Frf frf;
  frf.quantity = Quantity::kDisplacement;
  const Eigen::Index lines = static_cast<Eigen::Index>(t.Column("freq_hz").size());
  frf.freq_hz = t.Column("freq_hz");
  frf.h.resize(lines, 2);
  frf.coherence.resize(lines, 2);
  for (int j = 0; j < 2; ++j) {
    const std::string n = "x" + std::to_string(j + 1);
    frf.h.col(j).real() = t.Column(n + "_re");
    frf.h.col(j).imag() = t.Column(n + "_im");
    frf.coherence.col(j) = t.Column(n + "_coh");
  }
  const CsvTable ref = ReadCsv(TestData("plscf_poles.csv"));
  const Eigen::VectorXd fmin = ref.Column("fmin_hz"), fmax = ref.Column("fmax_hz"),
                        order = ref.Column("order");
  const Eigen::VectorXd re = ref.Column("re"), im = ref.Column("im");
  int cases = 0;
  for (Eigen::Index start = 0; start < order.size();) {
    Eigen::Index end = start;
    while (end < order.size() && order[end] == order[start] && fmin[end] == fmin[start]) ++end;
    const int p = static_cast<int>(order[start]);
    const PoleSet got = LscfPoles(frf, fmin[start], fmax[start], p);
    ASSERT_EQ(got.lambda.size(), end - start);
    for (Eigen::Index i = start; i < end; ++i) {
      const cd want(re[i], im[i]);
      double best = 1e300;
      for (Eigen::Index k = 0; k < got.lambda.size(); ++k)
        best = std::min(best, std::abs(got.lambda[k] - want));
      EXPECT_LT(best, 1e-6 * std::abs(want))
          << "order " << p << " band " << fmin[start] << ".." << fmax[start] << " pole " << want;
    }
    ++cases;
    start = end;
  }
  EXPECT_EQ(cases, 3);
}

// A digital 2-pole system y[n] = x[n] - a1 y[n-1] - a2 y[n-2] sampled at fs: its FRF at lines up
// to the Nyquist line is rational in W = exp(j w / fs), so order 2 returns the exact pole
// lambda = fs (ln r + j theta) (closed form).
TEST(Lscf, DigitalSystemPolesAreExact) {
  const double fs = 1000.0, r = 0.995, theta = 0.3;
  Frf frf;
  frf.quantity = Quantity::kAcceleration;
  const Eigen::Index lines = 501;  // 0 .. 500 Hz, the DC line included for LSCE
  frf.freq_hz = Eigen::VectorXd::LinSpaced(lines, 0.0, 500.0);
  frf.h.resize(lines, 1);
  frf.coherence = Eigen::MatrixXd::Ones(lines, 1);
  for (Eigen::Index k = 0; k < lines; ++k) {
    const cd z1 = std::exp(cd(0.0, -2 * std::numbers::pi * frf.freq_hz[k] / fs));
    frf.h(k, 0) = 1.0 / (1.0 - 2 * r * std::cos(theta) * z1 + r * r * z1 * z1);
  }
  const PoleSet p = LscfPoles(frf, 0, 0, 2);
  const cd want = fs * cd(std::log(r), theta);
  ASSERT_EQ(p.lambda.size(), 2);
  const cd got = p.lambda[0].imag() > 0 ? p.lambda[0] : p.lambda[1];
  EXPECT_LT(std::abs(got - want), 1e-9 * std::abs(want)) << got << " vs " << want;
  // LSCE: the inverse DFT of those lines is the impulse response r^n sin((n+1) theta) / sin(theta)
  // wrapped over the period, still a sum of the same two exponentials.
  const PoleSet q = LscePoles(frf, 2);
  ASSERT_EQ(q.lambda.size(), 2);
  const cd got_lsce = q.lambda[0].imag() > 0 ? q.lambda[0] : q.lambda[1];
  EXPECT_LT(std::abs(got_lsce - want), 1e-9 * std::abs(want)) << got_lsce << " vs " << want;
}

TEST(Stabilization, ChoosesTheChainModes) {
  // Closed-form receptance of the chain (test_support.hpp) and its damped poles from the state
  // matrix eigenvalues (model core is not used: the 2x2 quadratic eigenproblem by hand).
  const double m1 = 1.2, m2 = 0.8, k1 = 3000, k2 = 2000, c1 = 0.9, c2 = 0.8;
  const Frf frf = testing::ChainFrf(m1, m2, k1, k2, c1, c2, 1, 0.05, 800);
  StabilizationOptions o;
  o.max_order = 24;
  const StabilizationDiagram d = BuildStabilizationDiagram(frf, o);
  ASSERT_EQ(d.selected.size(), 2u);
  // Reference: numpy.linalg.eigvals of the first-order state matrix [[0, I], [-M^-1 K, -M^-1 C]]
  // of this chain: |lambda| / 2 pi = 5.34662 and 11.84407 Hz, zeta = -Re(lambda) / |lambda| =
  // 0.0055615 and 0.0137265.
  EXPECT_NEAR(d.selected[0].freq_hz, 5.3466207561948496, 1e-4 * 5.35);
  EXPECT_NEAR(d.selected[1].freq_hz, 11.844067994366151, 1e-4 * 11.84);
  EXPECT_NEAR(d.selected[0].zeta, 0.005561465600721372, 0.01 * 0.00556);
  EXPECT_NEAR(d.selected[1].zeta, 0.013726464215196884, 0.01 * 0.0137);
  EXPECT_EQ(d.orders.front(), 4);
  EXPECT_EQ(d.orders.back(), 24);
  int in_clusters = 0;
  for (const DiagramPole& p : d.poles) in_clusters += p.cluster >= 0;
  EXPECT_GE(in_clusters, 10);
}

TEST(Stabilization, OrdersAndOptionsAreValidated) {
  StabilizationOptions o;
  ParseOrders("6:30", o);
  EXPECT_EQ(o.min_order, 6);
  EXPECT_EQ(o.max_order, 30);
  ParseOrders("2:40:4", o);
  EXPECT_EQ(o.order_step, 4);
  EXPECT_THROW(ParseOrders("30:6", o), InputError);
  EXPECT_THROW(ParseOrders("abc", o), InputError);
  EXPECT_THROW(ParseOrders("4:x", o), InputError);
  EXPECT_THROW(ParseOrders("4:8:2:1", o), InputError);
  StabilizationOptions bad;
  bad.mac_min = 1.5;
  EXPECT_THROW(bad.Validate(), InputError);
}

}  // namespace
}  // namespace vibid::ident
