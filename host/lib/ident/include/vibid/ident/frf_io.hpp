// FRF files: CSV (the toolkit's own) and Universal File Format dataset 58 (ASCII), so FRFs open in
// other modal software.
//
// CSV: one header row, `freq_hz` and per response NAME_re, NAME_im, NAME_coh, then rows, so every
// CSV reader opens it with its defaults; the metadata in a JSON sidecar beside it (FRF.csv.json):
//   {"format": "vibid-frf", "version": 1, "columns": [...], "kind": "accelerance",
//    "estimator": "h1", "averages": 5, "exp_window_tau_s": 0, ..., "force": "force_n"}
// Files written before the sidecar opened with a comment line, still read:
//   # vibid-frf kind=accelerance estimator=h1 averages=5 exp_window_tau_s=0 force=force_n
//
// UFF58: one dataset per response (function type 4, FRF; complex double, even abscissa,
// 4E20.12 per data line) and one per coherence (function type 6; real double). Response j is
// node j+1, the reference (force) node is given; direction +X (1), the rig's axis. Ordinate
// types: 8 displacement, 11 velocity, 12 acceleration over 13 force. The abscissa start and step
// are written in the standard's E13.5 fields, so frequencies read back to about 6 digits.
#pragma once

#include <string>
#include <string_view>

#include "vibid/ident/spectral.hpp"

namespace vibid::ident {

/// The CSV's text: header row and rows (the metadata goes in the sidecar: FormatFrfSidecar).
std::string FormatFrfCsv(const Frf& frf);
/// InputError naming the source and problem (missing freq_hz, unpaired columns, bad metadata).
/// Reads the opening metadata line of files written before the sidecar; without one (and
/// without the sidecar, which LoadFrf applies) the FRF is a receptance that measured its kind.
Frf ParseFrfCsv(std::string_view text, const std::string& source);
/// The sidecar of an FRF CSV: its path with ".json" added.
std::string FrfSidecarPath(const std::string& csv_path);
/// The sidecar's JSON: kind, estimator, averages, windows, what was measured, the force.
std::string FormatFrfSidecar(const Frf& frf);
/// Applies a sidecar to an FRF read from its CSV. InputError naming `source` for a file that is
/// not a vibid-frf sidecar, an unknown key, a bad value, or columns other than the CSV's.
void ApplyFrfSidecar(std::string_view json, const std::string& source, Frf& frf);
/// True when the text looks like an FRF CSV (metadata line or freq_hz header).
bool LooksLikeFrfCsv(std::string_view text);

/// `reference_node` is the node number written for the force (1-based).
std::string FormatUff58(const Frf& frf, int reference_node);
/// Reads every dataset 58 of function type 4 (and 6 for coherence) that share one abscissa
/// into an Frf; other datasets are skipped. InputError with the line number on malformed input.
Frf ParseUff58(std::string_view text, const std::string& source);

/// Reads a file by its extension: .uff/.unv → UFF58, otherwise CSV with its sidecar when there
/// is one.
Frf LoadFrf(const std::string& path);
/// Writes by extension, atomically: UFF58 (reference node `reference_node`), or the CSV and its
/// sidecar (the sidecar first).
void WriteFrf(const Frf& frf, const std::string& path, int reference_node);
/// Writes by extension (.uff/.unv → UFF58 with reference node `reference_node`), atomically.
std::string FormatFrfForPath(const Frf& frf, const std::string& path, int reference_node);

}  // namespace vibid::ident
