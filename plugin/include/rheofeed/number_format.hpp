// SPDX-License-Identifier: MIT
/// @file number_format.hpp
/// The one number formatter of rheofeed's messages and text files. Standard library only
/// (header-only in the laws layer), so every layer and tool prints a number the same way.
#pragma once

#include <cstdio>
#include <string>

namespace rheofeed {

/// `value` printed with `significant_digits` significant digits in printf's "%.*g" form
/// (shortest of fixed and exponent notation, trailing zeros dropped): formatNumber(0.1) is
/// "0.1", formatNumber(1e300) "1e+300", formatNumber(1.0 / 3, 3) "0.333"; non-finite values
/// print as "inf", "-inf" or "nan". The default of 6 digits is what `std::ostream << value`
/// prints, so messages built either way read the same.
inline std::string formatNumber(double value, int significant_digits = 6) {
  char buffer[40];  // "%.17g" of any double, sign and exponent included, fits in 25
  std::snprintf(buffer, sizeof buffer, "%.*g", significant_digits, value);
  return buffer;
}

}  // namespace rheofeed
