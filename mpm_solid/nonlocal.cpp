#include "mpm_solid/nonlocal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>

namespace outburst::mpm {

std::vector<double> nonlocal_average(const std::vector<Vec<2>>& x, const std::vector<int>& members,
                                     const std::vector<double>& weight, const std::vector<double>& value,
                                     double radius) {
  if (!(radius > 0)) throw std::invalid_argument("nonlocal_average: the radius must be positive");
  if (value.size() != members.size() || weight.size() != members.size())
    throw std::invalid_argument("nonlocal_average: one value and one weight per member");
  const int n = static_cast<int>(members.size());
  std::vector<double> average(members.size());
  if (n == 0) return average;
  // Bins of side R: every neighbour of a particle lies in its bin or one of
  // the eight around it. A bin is a key of two 32-bit coordinates.
  const auto coordinate = [&](double v) { return static_cast<std::int64_t>(std::floor(v / radius)); };
  const auto key = [](std::int64_t bx, std::int64_t by) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(bx)) << 32) | static_cast<std::uint32_t>(by);
  };
  std::vector<std::pair<std::uint64_t, int>> binned(members.size());
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n; ++k) {
    const Vec<2>& xk = x[members[k]];
    binned[k] = {key(coordinate(xk.x()), coordinate(xk.y())), k};
  }
  std::sort(binned.begin(), binned.end());
  const double r2 = radius * radius;
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n; ++k) {
    const Vec<2>& xk = x[members[k]];
    const std::int64_t bx = coordinate(xk.x()), by = coordinate(xk.y());
    double weighted = 0, weights = 0;
    for (std::int64_t ix = bx - 1; ix <= bx + 1; ++ix)
      for (std::int64_t iy = by - 1; iy <= by + 1; ++iy) {
        const std::uint64_t b = key(ix, iy);
        auto it = std::lower_bound(binned.begin(), binned.end(), std::pair<std::uint64_t, int>{b, 0});
        for (; it != binned.end() && it->first == b; ++it) {
          const int j = it->second;
          const double d2 = (x[members[j]] - xk).squaredNorm();
          if (d2 >= r2) continue;
          const double bell = 1 - d2 / r2;
          const double w = weight[j] * bell * bell;
          weighted += w * value[j];
          weights += w;
        }
      }
    average[k] = weights > 0 ? weighted / weights : value[k];
  }
  return average;
}

}  // namespace outburst::mpm
