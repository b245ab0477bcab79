#pragma once
// A scalar that may vary in time: constant, or piecewise linear through (t, v)
// points and held constant before the first and after the last point. Boundary
// values use it so a scene can ramp a face pressure or switch a flux off.

#include <algorithm>
#include <cassert>
#include <utility>
#include <vector>

namespace outburst {

class TimeFunction {
 public:
  TimeFunction() = default;
  explicit TimeFunction(double constant) : points_{{0.0, constant}} {}
  // Points must be sorted by strictly increasing time (the scene reader checks).
  explicit TimeFunction(std::vector<std::pair<double, double>> points)
      : points_(std::move(points)) {
    assert(!points_.empty());
  }

  double operator()(double t) const {
    if (t <= points_.front().first) return points_.front().second;
    if (t >= points_.back().first) return points_.back().second;
    const auto upper = std::upper_bound(points_.begin(), points_.end(), t,
                                        [](double x, const auto& p) { return x < p.first; });
    const auto lower = upper - 1;
    const double w = (t - lower->first) / (upper->first - lower->first);
    return (1.0 - w) * lower->second + w * upper->second;
  }

 private:
  std::vector<std::pair<double, double>> points_{{0.0, 0.0}};
};

}  // namespace outburst
