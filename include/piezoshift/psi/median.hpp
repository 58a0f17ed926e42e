#pragma once
// The median of a set of values (the upper middle one for an even count; 0 for none), as the
// fits' unit of modulation takes it (phase_fits.cpp, frame_pose.cpp).
#include <algorithm>
#include <cstddef>
#include <vector>

namespace piezoshift::psi {

inline double median_of(std::vector<double> v) {
  if (v.empty())
    return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace piezoshift::psi
