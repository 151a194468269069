// Offline Butterworth low-pass, used to separate a slow disturbance (a hand push) from d_hat.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "vibid/dob/discretize.hpp"

namespace vibid::dob {

/// Digital Butterworth low-pass of any order >= 1 as second-order sections: the analog prototype
/// pre-warped to cutoff_hz and mapped by Tustin (what scipy.signal.butter(order, cutoff_hz,
/// fs=fs_hz, output='sos') computes). InputError unless 0 < cutoff_hz < fs_hz / 2.
std::vector<SosSection> ButterworthLowpass(int order, double cutoff_hz, double fs_hz);

/// Forward-backward (zero-phase) filtering with odd extension of 3 * (2 sections + 1) samples at
/// each end and steady-state initial conditions, as scipy.signal.sosfiltfilt. The magnitude
/// response is squared. InputError when the signal is not longer than the extension.
Eigen::VectorXd FiltFilt(const std::vector<SosSection>& sos,
                         const Eigen::Ref<const Eigen::VectorXd>& x);

}  // namespace vibid::dob
