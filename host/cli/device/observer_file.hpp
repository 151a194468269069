// The fixed-point observer inside a design file written by `vibid dob design`.
#pragma once

#include <string>

#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::cli {

/// The validated description a design file carries; InputError naming the file otherwise.
fixed::FilterDescription LoadObserverDescription(const std::string& path);

}  // namespace vibid::cli
