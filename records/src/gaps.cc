#include "gaps.h"

#include <cmath>

namespace mbid::records::internal {

int FirstGap(const std::vector<double>& values) {
  for (size_t j = 0; j < values.size(); ++j) {
    if (std::isnan(values[j])) return static_cast<int>(j);
  }
  return -1;
}

int FillGapsLinear(std::vector<double>* values, int* unfillable) {
  std::vector<double>& v = *values;
  const int n = static_cast<int>(v.size());
  *unfillable = -1;
  if (n > 0 && std::isnan(v.front())) {
    *unfillable = 0;
    return 0;
  }
  for (int j = n - 1; j >= 0 && std::isnan(v[static_cast<size_t>(j)]); --j) *unfillable = j;
  if (*unfillable >= 0) return 0;
  int filled = 0;
  int last = 0;  // last sample with a value
  for (int j = 1; j < n; ++j) {
    if (std::isnan(v[static_cast<size_t>(j)])) continue;
    const int run = j - last - 1;
    for (int k = last + 1; k < j; ++k) {
      // The uniform grid makes the sample index proportional to time.
      const double w = static_cast<double>(k - last) / static_cast<double>(j - last);
      v[static_cast<size_t>(k)] =
          (1.0 - w) * v[static_cast<size_t>(last)] + w * v[static_cast<size_t>(j)];
    }
    filled += run;
    last = j;
  }
  return filled;
}

}  // namespace mbid::records::internal
