#pragma once
// Analytic solutions of the poroelastic checks: Terzaghi's consolidation
// (cases/terzaghi), Mandel's problem (cases/mandel) and Cryer's sphere
// (cases/cryer).

#include <cmath>
#include <vector>

#include "coupler/model.hpp"

namespace outburst::testing {

// Terzaghi: p(z, t) = sum 2 p0 / M_m sin(M_m z / H) exp(-M_m^2 T), z from the
// drained top, M_m = pi (2m + 1) / 2, T = c_v t / H^2.
struct Terzaghi {
  double H, p0, cv;
  // A column of height H under the load q, with Young's modulus and Poisson
  // ratio (constrained modulus M = E (1 - nu) / ((1 + nu)(1 - 2 nu))), storage
  // S, Biot coefficient alpha and mobility k / mu: p0 = alpha q / (alpha^2 +
  // S M), c_v = (k / mu) / (S + alpha^2 / M).
  static Terzaghi of_column(double height, double load, double e, double nu, double storage, double alpha,
                            double mobility) {
    const double m = constrained_modulus(e, nu);
    return {height, alpha * load / (alpha * alpha + storage * m), mobility / (storage + alpha * alpha / m)};
  }
  static double constrained_modulus(double e, double nu) { return e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)); }
  double pressure(double z, double t) const {
    double sum = 0;
    for (int m = 0; m < 400; ++m) {
      const double mm = 3.14159265358979323846 * (2 * m + 1) / 2;
      sum += 2 * p0 / mm * std::sin(mm * z / H) * std::exp(-mm * mm * cv * t / (H * H));
    }
    return sum;
  }
  // Downward displacement at height y above the fixed bottom: the integral of
  // the strain (q - alpha p) / M from the bottom up (the undrained share
  // included through p), by the midpoint rule.
  double displacement(double y, double t, double q, double alpha, double modulus) const {
    const int n = 200;
    double u = 0;
    for (int k = 0; k < n; ++k) {
      const double at = (k + 0.5) * y / n;
      u += (q - alpha * pressure(H - at, t)) / modulus * y / n;
    }
    return u;
  }
};

// Mandel's problem in plane strain (Abousleiman et al. 1996): a specimen 2a
// wide pressed by rigid frictionless plates with 2F per metre of depth, sides
// free and drained. With tan(a_n) = (1 - nu) / (nu_u - nu) a_n,
//   p(x, t) = 2 F B (1 + nu_u) / (3a) sum sin a_n / (a_n - sin a_n cos a_n)
//             (cos(a_n x / a) - cos a_n) exp(-a_n^2 c t / a^2),
//   u_y(b, t) = b F / (G a) [-(1 - nu) / 2 + (1 - nu_u) sum sin a_n cos a_n /
//             (a_n - sin a_n cos a_n) exp(-a_n^2 c t / a^2)].
struct Mandel {
  double a, b, force, shear, nu, nu_u, skempton, c;
  std::vector<double> roots;

  Mandel(double a_, double b_, double force_, double e, double nu_, double storage, double alpha, double mobility)
      : a(a_), b(b_), force(force_), nu(nu_) {
    shear = e / (2 * (1 + nu));
    const double bulk = e / (3 * (1 - 2 * nu)), biot_modulus = 1 / storage;
    const double undrained = bulk + alpha * alpha * biot_modulus;
    skempton = alpha * biot_modulus / undrained;
    nu_u = (3 * undrained - 2 * shear) / (2 * (3 * undrained + shear));
    c = mobility * biot_modulus * (bulk + 4 * shear / 3) / (undrained + 4 * shear / 3);
    // sin x - k x cos x changes sign once in (0, pi/2) and in each (n pi, n pi + pi/2).
    const double k = (1 - nu) / (nu_u - nu), pi = 3.14159265358979323846;
    for (int n = 0; n < 300; ++n) {
      double lo = n == 0 ? 1e-9 : n * pi, hi = n * pi + pi / 2;
      const auto f = [k](double x) { return std::sin(x) - k * x * std::cos(x); };
      const bool rising = f(lo) < 0;
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (lo + hi);
        ((f(mid) < 0) == rising ? lo : hi) = mid;
      }
      roots.push_back(0.5 * (lo + hi));
    }
  }
  double initial_pressure() const { return force * skempton * (1 + nu_u) / (3 * a); }
  double pressure(double x, double t) const {
    double sum = 0;
    for (double r : roots)
      sum += std::sin(r) / (r - std::sin(r) * std::cos(r)) * (std::cos(r * x / a) - std::cos(r)) *
             std::exp(-r * r * c * t / (a * a));
    return 2 * force * skempton * (1 + nu_u) / (3 * a) * sum;
  }
  double settlement(double t) const {  // downward, of the plate
    double sum = 0;
    for (double r : roots)
      sum += std::sin(r) * std::cos(r) / (r - std::sin(r) * std::cos(r)) * std::exp(-r * r * c * t / (a * a));
    return -b * force / (shear * a) * (-(1 - nu) / 2 + (1 - nu_u) * sum);
  }
};

// Cryer's sphere (Verruijt 2016, Theory and problems of poroelasticity, as
// the Beaver code's documentation gives it): the pressure at the centre of a
// sphere of radius a whose surface drains from t = 0, over the undrained p0,
//   eta sum (sin x_j - x_j) / ((eta - 1) sin x_j + eta x_j cos x_j / 2)
//       exp(-x_j^2 c_v t / a^2),
// x_j the positive roots of (1 - eta x^2 / 2) tan x = x, with
// eta = (1 - nu) / (1 - 2 nu) (1 + K S / alpha^2) and
// c_v = (k / mu) (K + 4 G / 3) / (alpha^2 + S (K + 4 G / 3)).
struct Cryer {
  double a, eta, cv;
  std::vector<double> roots;

  Cryer(double radius, double e, double nu, double storage, double alpha, double mobility) : a(radius) {
    const double bulk = e / (3 * (1 - 2 * nu)), shear = e / (2 * (1 + nu)), oedometric = bulk + 4 * shear / 3;
    eta = (1 - nu) / (1 - 2 * nu) * (1 + bulk * storage / (alpha * alpha));
    cv = mobility * oedometric / (alpha * alpha + storage * oedometric);
    // (1 - eta x^2 / 2) sin x - x cos x has no poles: its sign changes
    // bracket the roots, each refined by bisection.
    const auto f = [this](double x) { return (1 - eta * x * x / 2) * std::sin(x) - x * std::cos(x); };
    const double step = 0.01;
    for (double lo = step; roots.size() < 400; lo += step) {
      double left = lo, right = lo + step;
      if ((f(left) < 0) == (f(right) < 0)) continue;
      const bool rising = f(left) < 0;
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (left + right);
        ((f(mid) < 0) == rising ? left : right) = mid;
      }
      roots.push_back(0.5 * (left + right));
    }
  }
  // p(0, t) / p0.
  double centre(double t) const {
    double sum = 0;
    for (double x : roots)
      sum += (std::sin(x) - x) / ((eta - 1) * std::sin(x) + eta * x * std::cos(x) / 2) *
             std::exp(-x * x * cv * t / (a * a));
    return eta * sum;
  }
};

// Mandel: the mean seepage pressure on the specimen's centre line x = 0 [Pa].
inline double centre_pressure(coupling::CoupledModel<2>& model) {
  const auto p = model.seepage().nodal_pressure();
  const auto& mesh = model.mapping().mesh();
  double centre = 0;
  int count = 0;
  for (std::size_t i = 0; i < mesh.num_nodes(); ++i)
    if (mesh.nodes[i].x() < 1e-9) {
      centre += p[i];
      ++count;
    }
  return centre / count;
}

}  // namespace outburst::testing
