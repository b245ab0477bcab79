#include "mpm_solid/nonlocal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>

namespace outburst::mpm {

template <int Dim>
std::vector<double> nonlocal_average(const std::vector<Vec<Dim>>& x, const std::vector<int>& members,
                                     const std::vector<double>& weight, const std::vector<double>& value,
                                     double radius) {
  if (!(radius > 0)) throw std::invalid_argument("nonlocal_average: the radius must be positive");
  if (value.size() != members.size() || weight.size() != members.size())
    throw std::invalid_argument("nonlocal_average: one value and one weight per member");
  const int n = static_cast<int>(members.size());
  std::vector<double> average(members.size());
  if (n == 0) return average;
  // Bins of side R: every neighbour of a particle lies in its bin or one of
  // the 3^Dim - 1 around it.
  using Bin = std::array<std::int64_t, Dim>;
  const auto bin_of = [&](const Vec<Dim>& v) {
    Bin b;
    for (int d = 0; d < Dim; ++d) b[d] = static_cast<std::int64_t>(std::floor(v[d] / radius));
    return b;
  };
  std::vector<std::pair<std::uint64_t, int>> binned(members.size());
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n; ++k) binned[k] = {bin_key<Dim>(bin_of(x[members[k]])), k};
  std::sort(binned.begin(), binned.end());
  const double r2 = radius * radius;
  const auto gather = [&](const Vec<Dim>& xk, const Bin& b, double& weighted, double& weights) {
    const std::uint64_t bin = bin_key<Dim>(b);
    auto it = std::lower_bound(binned.begin(), binned.end(), std::pair<std::uint64_t, int>{bin, 0});
    for (; it != binned.end() && it->first == bin; ++it) {
      const int j = it->second;
      const double d2 = (x[members[j]] - xk).squaredNorm();
      if (d2 >= r2) continue;
      const double bell = 1 - d2 / r2;
      const double w = weight[j] * bell * bell;
      weighted += w * value[j];
      weights += w;
    }
  };
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n; ++k) {
    const Vec<Dim>& xk = x[members[k]];
    const Bin home = bin_of(xk);
    double weighted = 0, weights = 0;
    Bin b;
    for (b[0] = home[0] - 1; b[0] <= home[0] + 1; ++b[0])
      for (b[1] = home[1] - 1; b[1] <= home[1] + 1; ++b[1]) {
        if constexpr (Dim == 2) {
          gather(xk, b, weighted, weights);
        } else {
          for (b[2] = home[2] - 1; b[2] <= home[2] + 1; ++b[2]) gather(xk, b, weighted, weights);
        }
      }
    average[k] = weights > 0 ? weighted / weights : value[k];
  }
  return average;
}

template std::vector<double> nonlocal_average<2>(const std::vector<Vec<2>>&, const std::vector<int>&,
                                                 const std::vector<double>&, const std::vector<double>&, double);
template std::vector<double> nonlocal_average<3>(const std::vector<Vec<3>>&, const std::vector<int>&,
                                                 const std::vector<double>&, const std::vector<double>&, double);

}  // namespace outburst::mpm
