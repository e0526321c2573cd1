// Order statistics shared by the mappers, the toolbox and the evaluation.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace tessera {

// The upper median: the element at index size/2 once sorted (for an even count, the
// larger of the two middle values); 0 for no values.
inline double UpperMedian(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace tessera
