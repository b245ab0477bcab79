#pragma once
// Self-similar drainage of a gas-filled half-space through its face, computed
// independently of the finite element code by ODE shooting.
//
// For (A/4) P^(-3/4) P_t = lambda P_xx on x > 0 with P(0, t) = P_f, P(x, 0) = P0,
// P = P0 f(z), z = x / sqrt(D0 t), D0 = 4 lambda P0^(3/4) / A, turns the PDE into
//     f'' = -(z / 2) f^(-3/4) f',   f(0) = P_f / P0,   f(inf) = 1.
// The slope f'(0) is found by bisection so that f reaches 1 far away.
// Cumulative emission per unit face area: Q(t) = 2 lambda P0 f'(0) sqrt(t / D0).

#include <algorithm>
#include <cmath>
#include <vector>

namespace outburst::testing {

class DrainageSimilarity {
 public:
  explicit DrainageSimilarity(double face_ratio, double z_max = 10.0, double dz = 2e-4)
      : f0_(face_ratio), dz_(dz), n_(static_cast<int>(z_max / dz)) {
    double lo = 0, hi = 1;
    while (shoot(hi, false) < 1) hi *= 2;
    for (int i = 0; i < 80; ++i) {
      const double mid = 0.5 * (lo + hi);
      (shoot(mid, false) < 1 ? lo : hi) = mid;
    }
    slope_ = 0.5 * (lo + hi);
    shoot(slope_, true);
  }

  double slope_at_face() const { return slope_; }
  // f at z = x / sqrt(D0 t), linearly interpolated.
  double f(double z) const {
    const double s = z / dz_;
    const int i = static_cast<int>(s);
    if (i >= n_) return profile_.back();
    return profile_[i] + (s - i) * (profile_[i + 1] - profile_[i]);
  }
  // integral of (1 - f^(1/4)) dz: emitted gas in similarity units.
  double deficit_integral() const {
    double sum = 0;
    for (int i = 0; i < n_; ++i)
      sum += 0.5 * dz_ * ((1 - std::pow(profile_[i], 0.25)) + (1 - std::pow(profile_[i + 1], 0.25)));
    return sum;
  }

 private:
  // RK4 for (f, f'); returns f at z_max, or a value above 1 as soon as f passes 1.
  double shoot(double slope, bool keep) {
    double y = f0_, v = slope, z = 0;
    if (keep) profile_.assign(1, y);
    const auto rhs = [](double zz, double ff, double vv) { return -0.5 * zz * std::pow(ff, -0.75) * vv; };
    for (int i = 0; i < n_; ++i) {
      const double k1y = v, k1v = rhs(z, y, v);
      const double k2y = v + 0.5 * dz_ * k1v, k2v = rhs(z + 0.5 * dz_, y + 0.5 * dz_ * k1y, v + 0.5 * dz_ * k1v);
      const double k3y = v + 0.5 * dz_ * k2v, k3v = rhs(z + 0.5 * dz_, y + 0.5 * dz_ * k2y, v + 0.5 * dz_ * k2v);
      const double k4y = v + dz_ * k3v, k4v = rhs(z + dz_, y + dz_ * k3y, v + dz_ * k3v);
      y += dz_ / 6 * (k1y + 2 * k2y + 2 * k3y + k4y);
      v += dz_ / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      z += dz_;
      if (keep) profile_.push_back(y);
      if (!keep && y > 1) return y;
    }
    return y;
  }

  double f0_, dz_;
  int n_;
  double slope_ = 0;
  std::vector<double> profile_;
};

// Advances a drainage run to t = 1 in geometric steps from a tiny first one
// (the solution is self-similar in sqrt(t)), refined with the mesh: the step
// ratio - 1 halves as the cells along the strip double.
template <class Solver>
void drain_to_unit_time(Solver& s, int cells) {
  double dt = 1e-4 / (cells * cells), t = 0;
  const double growth = 1 + 4.0 / cells;
  while (t < 1) {
    const double h = std::min(dt, 1 - t);
    s.advance(h);
    t += h;
    dt *= growth;
  }
}

}  // namespace outburst::testing
