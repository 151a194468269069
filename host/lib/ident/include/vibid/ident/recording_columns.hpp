// The channel names of the board's recordings (`vibid acquire`, `vibid log pull`:
// docs/file-formats.md), which the identification commands read by default: a recording straight
// off the board needs no column option. The board names a channel by its stem (force1, acc2, ...)
// and its unit suffix (n, m_s2); host/device's log table writes them, and a test holds both to the
// same names.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace vibid::ident {

/// "force1_n": the load cell the modal and mass tests' hammer is measured with.
std::string ForceColumn();

/// "acc<P>_m_s2": the accelerometer on mass `position` (counted from 1).
std::string AccelerationColumn(std::size_t position);

/// "acc1_m_s2,...,acc<N>_m_s2": one accelerometer per mass of an N-mass chain, in order.
std::string AccelerationColumns(std::size_t masses);

}  // namespace vibid::ident
