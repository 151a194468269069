// CSV rows of fixed-point quantities: the board's calibrated columns hold q x full_scale / 2^31,
// and their shortest decimal that keeps q is all a reader needs (csv.hpp writes the rest).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace vibid {

/// The rows FormatCsvRows writes, where column c holds a fixed-point quantity (`full_scales[c]` >
/// 0): a value q x full_scale / 2^31 with q whole (to within the double's rounding) is written as
/// the shortest decimal d that still gives q back as nearbyint(d / full_scale x 2^31) (0.0064, not
/// 0.006400000003539024: the digits beyond carry nothing of q), so a reader recovers the board's
/// number exactly and reads the value as written. Any other value, and every value of a column with
/// full scale 0, is written as its shortest round-trip decimal.
std::string FormatCsvRowsQ31(const std::vector<Eigen::VectorXd>& columns,
                             const std::vector<double>& full_scales);

}  // namespace vibid
