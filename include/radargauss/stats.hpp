// SPDX-License-Identifier: BSD-3-Clause
// The median, defined once: the middle value, or the mean of the two middle
// values for an even count.
#pragma once

#include <algorithm>
#include <vector>

namespace radargauss {

// `sorted` ascending and not empty.
inline double MedianOfSorted(const std::vector<double>& sorted) {
  const std::size_t n = sorted.size();
  return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

// 0 for no values.
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return MedianOfSorted(values);
}

}  // namespace radargauss
