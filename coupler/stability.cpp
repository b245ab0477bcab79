#include "coupler/stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

namespace outburst::coupling::stability {

namespace {

// The solid over one window as an exact linear map. With y = (eps, v, q, r),
// q the pressure it feels and r = dq/dt constant over the window:
//   eps' = v,  v' = -c v - kappa^2 / rho (M_c eps - alpha q),  q' = r.
struct SolidWindow {
  Eigen::Matrix4d map;  // exp(A window)
  // eps and v at the window's end from their start, the pressure's start and slope.
  Eigen::Vector2d end(double eps, double v, double q, double r) const {
    return (map * Eigen::Vector4d(eps, v, q, r)).head<2>();
  }
};

SolidWindow solid_window(const Regime& g, double kappa, double window) {
  Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
  const double k2 = kappa * kappa / g.density;
  a(0, 1) = 1;
  a(1, 0) = -k2 * g.p_wave_modulus;
  a(1, 1) = -g.damping;
  a(1, 2) = k2 * g.biot;
  a(2, 3) = 1;
  return {(a * window).exp()};
}

}  // namespace

std::vector<double> wavenumbers(const Regime& g) {
  if (!(g.length > 0) || !(g.cell > 0)) throw std::invalid_argument("stability: length and cell must be positive");
  const int modes = std::max(1, static_cast<int>(std::lround(g.length / g.cell)));
  std::vector<double> k;
  for (int j = 1; j <= modes; ++j) k.push_back((j - 0.5) * std::numbers::pi / g.length);
  return k;
}

double amplification(const Regime& g, const Window& w, double kappa) {
  const double dt = w.size, alpha = g.biot, s = g.storage;
  const double sine = std::sin(0.5 * kappa * g.cell);
  const double drain = g.mobility * 4 / (g.cell * g.cell) * sine * sine * dt;  // backward Euler, one window
  const SolidWindow solid = solid_window(g, kappa, dt);
  // The pressure felt from p (start) and p1 (end): start and slope.
  const auto felt = [&](double p, double p1) {
    return w.pressure == Pressure::ramp ? Eigen::Vector2d(p, (p1 - p) / dt) : Eigen::Vector2d(p1, 0);
  };

  if (w.iterated) {
    // State (eps, v, p). Converged: the fluid sees this window's volume
    // change, S (p1 - p) + alpha (eps1 - eps) = -drain p1, with eps1 linear in
    // p1: eps1 = base + per_p1 p1.
    Eigen::Matrix3d amp;
    for (int c = 0; c < 3; ++c) {
      const double eps = c == 0, v = c == 1, p = c == 2;
      const Eigen::Vector2d q0 = felt(p, 0), q1 = felt(0, 1);
      const Eigen::Vector2d base = solid.end(eps, v, q0[0], q0[1]), per_p1 = solid.end(0, 0, q1[0], q1[1]);
      const double p1 = (s * p - alpha * (base[0] - eps)) / (s + alpha * per_p1[0] + drain);
      amp.col(c) << base + per_p1 * p1, p1;
    }
    return amp.eigenvalues().cwiseAbs().maxCoeff();
  }

  // One pass: state (eps, v, p, eps_prev, p_prev); the fluid sees the last
  // window's volume change, with the fixed-stress split also the extra
  // storage beta and its source beta (p - p_prev).
  const double beta = w.fixed_stress ? alpha * alpha / g.bulk_modulus : 0.0;
  Eigen::Matrix<double, 5, 5> amp;
  for (int c = 0; c < 5; ++c) {
    const double eps = c == 0, v = c == 1, p = c == 2, eps_prev = c == 3, p_prev = c == 4;
    const double p1 = ((s + beta) * p - alpha * (eps - eps_prev) + beta * (p - p_prev)) / (s + beta + drain);
    const Eigen::Vector2d q = felt(p, p1);
    amp.col(c) << solid.end(eps, v, q[0], q[1]), p1, eps, p;
  }
  return amp.eigenvalues().cwiseAbs().maxCoeff();
}

Growth growth(const Regime& g, const Window& w) {
  if (!(w.size > 0)) throw std::invalid_argument("stability: the window must be positive");
  Growth worst{-std::numeric_limits<double>::infinity(), 0};
  for (double kappa : wavenumbers(g)) {
    const double rate = std::log(amplification(g, w, kappa)) / w.size;
    if (rate > worst.rate) worst = {rate, kappa};
  }
  return worst;
}

double smallest_stable_window(const Regime& g, Window w, double from, double up_to) {
  for (w.size = from; w.size <= up_to; w.size *= std::exp2(0.125))
    if (growth(g, w).rate <= 0) return w.size;
  return 0;
}

}  // namespace outburst::coupling::stability
