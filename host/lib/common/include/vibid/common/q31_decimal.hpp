// The board's calibrated values are fixed-point: q x full_scale / 2^31 with q a whole Q31 word.
// In double that product carries digits that say nothing of q (640 encoder counts of 100 000 per
// metre give 0.006400000003539024 m); the shortest decimal that still rounds back to q (0.0064)
// is what a reader wants to see, and what every CSV reader then reads.
#pragma once

namespace vibid {

/// The double of the shortest decimal d with nearbyint(d / full_scale x 2^31) equal to that of
/// `value`, when `value` is q x full_scale / 2^31 for a whole q (to within the double's rounding
/// of that product); `value` itself otherwise (a decimated value carries fraction bits of q, and
/// full_scale <= 0 or a non-finite value has no grid). A reader recovers q from it as the board's
/// observer replay does (dob::ToQ31: nearbyint), and its shortest round-trip form is d.
double ShortestQ31Decimal(double value, double full_scale);

/// The double of a float32's shortest decimal (0.2f -> 0.2, not 0.20000000298023224): a value the
/// board or the wire holds in binary32 (a full scale, a scenario parameter) as written.
double ShortestFloat32Decimal(float value);

}  // namespace vibid
