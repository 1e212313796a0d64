#pragma once
// Numbers as text, for messages, reports and generated files: the one formatter of the project. Header-only, so
// every module (filter/ too) can use it without linking stvl_common.
#include <cstddef>
#include <cstdio>
#include <string>

namespace stvl {

// `value` with `decimals` digits after the point, as printf's "%.*f" (and std::fixed with setprecision): "0.9871",
// halves rounded to even ("0.5" with 0 decimals is "0"), "-0.00" kept, "nan" and "inf" as printf writes them.
inline std::string fixed(double value, int decimals) {
  char text[350];  // the longest finite double with up to 20 decimals fits
  const int n = std::snprintf(text, sizeof text, "%.*f", decimals, value);
  if (n >= 0 && static_cast<std::size_t>(n) < sizeof text) return text;
  std::string long_text(static_cast<std::size_t>(n) + 1, '\0');
  std::snprintf(long_text.data(), long_text.size(), "%.*f", decimals, value);
  long_text.resize(static_cast<std::size_t>(n));
  return long_text;
}

// `value` with at most `significant` significant digits, as printf's "%.*g": the default of `std::ostream <<`
// (6 digits: "0.05", "1e+06", "3.14159").
inline std::string general(double value, int significant = 6) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", significant, value);
  return text;
}

}  // namespace stvl
