#pragma once
// Order statistics shared by the sensors' statistics, the analyses and the benchmarks. Header-only.
#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

namespace stvl {

// Median of `values` (the mean of the two middle values for an even count); `if_empty` (NaN unless given) when
// there are none. Takes its copy to reorder (nth_element, not a full sort).
inline double median(std::vector<double> values, double if_empty = std::numeric_limits<double>::quiet_NaN()) {
  if (values.empty()) return if_empty;
  const auto mid = static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2 == 1) return values[static_cast<std::size_t>(mid)];
  const double upper = values[static_cast<std::size_t>(mid)];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

}  // namespace stvl
