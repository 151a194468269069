// Reading numbers and lists out of option text. Every front end parses its option values with
// these, so "is this a number" means the same thing for every option; each command keeps its own
// message because the message names the option and what the value is for.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vibid {

/// A number as a message echoes an option's value back ("%g": 0.001, 1800, 2.5e+07).
std::string OptionNumber(double value);

/// How a text failed to be a number.
enum class NumberText {
  kOk,
  kNotANumber,  ///< No number at its start, or one too large or too small for a double.
  kNotFinite,   ///< A number followed by other text, or inf / nan.
};

/// The whole of `text` as a finite double, with strtod's reading: leading blanks, a sign, decimal
/// or hexadecimal digits, an exponent. `value` is set whenever a number was read.
NumberText ParseNumber(std::string_view text, double& value);

/// The whole of `text` as an integer in `base` (0: 0x.. hexadecimal, 0.. octal, else decimal);
/// nothing when any of it is not, or it does not fit a long long.
std::optional<long long> ParseInteger(std::string_view text, int base = 10);

/// Whether an empty last item counts ("1,2," and "" end with one).
enum class TrailingEmpty { kKeep, kDrop };

/// "a,b,c" -> {"a", "b", "c"}. Empty items inside are kept so the caller can name the bad one; an
/// empty last item is kept or dropped by `trailing` (dropped, "" gives no item at all).
std::vector<std::string> SplitOptionList(std::string_view text,
                                         TrailingEmpty trailing = TrailingEmpty::kKeep);

}  // namespace vibid
