// SPDX-License-Identifier: BSD-3-Clause
// Summary statistics, defined once. The median: the middle value, or the
// mean of the two middle values for an even count.
#pragma once

#include <algorithm>
#include <cmath>
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

// The value below which a share q of `sorted` (ascending, not empty) lies:
// sorted[floor(q n)], the largest at q = 1.
inline double PercentileOfSorted(const std::vector<double>& sorted, double q) {
  return sorted[std::min(sorted.size() - 1, std::size_t(q * double(sorted.size())))];
}

// Mean, median, root mean square and maximum of a set of errors (all 0 for none).
struct ErrorStatistics {
  double mean = 0.0, median = 0.0, rmse = 0.0, max = 0.0;
};

inline ErrorStatistics Statistics(std::vector<double> values) {
  ErrorStatistics s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  double sum = 0.0, sum_sq = 0.0;
  for (const double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  s.mean = sum / double(n);
  s.median = MedianOfSorted(values);
  s.rmse = std::sqrt(sum_sq / double(n));
  s.max = values.back();
  return s;
}

}  // namespace radargauss
