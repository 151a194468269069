// Fuzzes the FRF readers: the toolkit's CSV (freq_hz and NAME_re/_im/_coh columns; its metadata
// in a sidecar, or a leading comment line in older files) and Universal File Format dataset 58
// (ASCII) as other modal software writes it. The first byte picks the reader (and whether LoadFrf's
// format sniffing sees the text first); the rest is the file's text. What a reader accepts must
// survive its writer: the written text reads back, and writing that again gives the same text
// (UFF58 keeps 6 digits of the abscissa, so text, not numbers, is what must be stable); the CSV
// writer and its sidecar keep every number bit for bit. The FRF is well formed: one line per
// frequency, finite values, coherence in [0, 1], one name per response.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_support.hpp"
#include "vibid/ident/frf_io.hpp"

namespace {

using namespace vibid;
using fuzz::Accepts;
using fuzz::Require;

void CheckShape(const ident::Frf& f) {
  Require(f.lines() > 0 && f.responses() > 0);
  Require(static_cast<std::size_t>(f.h.rows()) == f.lines() && f.coherence.rows() == f.h.rows() &&
          f.coherence.cols() == f.h.cols() && f.response_names.size() == f.responses());
  Require(f.freq_hz.allFinite() && f.h.allFinite() && f.coherence.allFinite());
  Require((f.coherence.array() >= 0.0).all() && (f.coherence.array() <= 1.0).all());
}

void CheckSame(const ident::Frf& a, const ident::Frf& b) {
  Require(a.lines() == b.lines() && a.responses() == b.responses() &&
          a.response_names == b.response_names && a.force_name == b.force_name &&
          a.quantity == b.quantity && a.estimator == b.estimator && a.averages == b.averages &&
          fuzz::Same(a.exp_window_tau_s, b.exp_window_tau_s));
  for (Eigen::Index i = 0; i < a.freq_hz.size(); ++i)
    Require(fuzz::Same(a.freq_hz[i], b.freq_hz[i]));
  for (Eigen::Index i = 0; i < a.h.size(); ++i) {
    Require(fuzz::Same(a.h.data()[i].real(), b.h.data()[i].real()) &&
            fuzz::Same(a.h.data()[i].imag(), b.h.data()[i].imag()));
    Require(fuzz::Same(a.coherence.data()[i], b.coherence.data()[i]));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t mode = data[0];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  // LoadFrf reads .uff/.unv as UFF58 and anything else as CSV; the sniffing is used to tell a
  // misnamed file apart.
  if ((mode & 2u) != 0) (void)ident::LooksLikeFrfCsv(text);
  const bool uff = (mode & 1u) != 0;
  std::optional<ident::Frf> frf;
  if (!Accepts([&] {
        frf = uff ? ident::ParseUff58(text, "fuzz.uff") : ident::ParseFrfCsv(text, "fuzz.csv");
      }))
    return 0;
  CheckShape(*frf);

  const int node = 1 + (mode >> 4);
  std::string written;
  std::string sidecar;  // the CSV's facts (force, quantity, estimator, ...) beside it
  Require(Accepts([&] {
    written = uff ? ident::FormatUff58(*frf, node) : ident::FormatFrfCsv(*frf);
    if (!uff) sidecar = ident::FormatFrfSidecar(*frf);
  }));
  std::optional<ident::Frf> again;
  Require(Accepts([&] {
    again =
        uff ? ident::ParseUff58(written, "again.uff") : ident::ParseFrfCsv(written, "again.csv");
    if (!uff) ident::ApplyFrfSidecar(sidecar, "again.csv.json", *again);
  }));
  CheckShape(*again);
  if (uff) {
    Require((uff ? ident::FormatUff58(*again, node) : ident::FormatFrfCsv(*again)) == written);
  } else {
    CheckSame(*frf, *again);
  }
  return 0;
}
