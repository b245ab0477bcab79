#pragma once
// The principal decomposition of a stress (the in-plane matrix under plane
// strain) and the stress whose tensile principal parts open cracks scale:
// the elastic-damage law's split of a stress into what a crack carries and
// what it does not (elastic_damage.cpp).

#include <cmath>

#include <Eigen/Eigenvalues>

#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

// Open cracks: tensile principal parts scaled by (1 - D) (or back, by 1/(1 - D)).
inline double crack(double principal_value, double factor) {
  return principal_value > 0 ? factor * principal_value : principal_value;
}

// The principal decomposition of a stress matrix (the in-plane one under
// plane strain), and the stress whose tensile principal parts are scaled.
template <int Dim>
struct Principal;

template <>
struct Principal<2> {
  double a, b;          // a >= b
  double cos, sin;      // the direction of a
  // Straight-line code, both cases computed and one chosen, as are the
  // damage law's: the plane's update runs them over SIMD lanes.
  Principal(double xx, double yy, double xy) {
    const double centre = 0.5 * (xx + yy);
    const double half = 0.5 * (xx - yy);
    const double radius = std::sqrt(half * half + xy * xy);
    // Half-angle formulas from cos 2t = half / radius, sin 2t = s_xy / radius:
    // no trigonometric calls in the innermost loop of the damage law. Where
    // the squares fall below the normal numbers (entries under 1e-154, as a
    // grid's round-off spreads through a body at rest) the radius keeps few
    // bits and may come out below |half|: cos 2t is held to [-1, 1], else the
    // half-angle roots turned NaN and the body with them. Above, the radius
    // is never below |half| and the bound changes nothing. By value, as the
    // yield screen's maxima are (drucker_prager.cpp: std::max's references
    // became masked loads there, which kept its lanes scalar).
    const double ratio = half / radius;
    const double cos2 = ratio > 1 ? 1.0 : (ratio < -1 ? -1.0 : ratio);
    const bool equal = radius == 0;  // any direction is principal
    a = equal ? centre : centre + radius;
    b = equal ? centre : centre - radius;
    const double c = std::sqrt(0.5 * (1 + cos2)), s = std::copysign(std::sqrt(0.5 * (1 - cos2)), xy);
    cos = equal ? 1.0 : c;
    sin = equal ? 0.0 : s;
  }
  explicit Principal(const Mat<2>& s) : Principal(s(0, 0), s(1, 1), s(0, 1)) {}
  double largest() const { return a; }
  double smallest() const { return b; }
  double sum() const { return a + b; }
  // The entries in Eigen's column-major order, each as Eigen formed
  // (crack(a) direction) direction^T + (crack(b) normal) normal^T.
  void cracked(double factor, double& xx, double& yx, double& xy, double& yy) const {
    const double ca = crack(a, factor), cb = crack(b, factor), nx = -sin, ny = cos;
    const double t0 = ca * cos, t1 = ca * sin, u0 = cb * nx, u1 = cb * ny;
    xx = t0 * cos + u0 * nx;
    yx = t1 * cos + u1 * nx;
    xy = t0 * sin + u0 * ny;
    yy = t1 * sin + u1 * ny;
  }
  void cracked(double factor, double* out) const { cracked(factor, out[0], out[1], out[2], out[3]); }
  Mat<2> cracked(double factor) const {
    Mat<2> m;
    cracked(factor, m.data());
    return m;
  }
};

template <>
struct Principal<3> {
  Mat<3> matrix;
  Vec<3> values;  // ascending
  Mat<3> axes;    // the columns; only where the values straddle zero
  explicit Principal(const Mat<3>& s) : matrix(s) {
    // A state all in tension, or all in compression, cracks without its
    // axes. Where they are needed, the iterative solver's: the closed form's
    // are not orthogonal where two principal values agree (by 7e-7 under
    // uniaxial strain, its two lateral stresses equal), and the stress
    // recomposed from them is off by as much.
    Eigen::SelfAdjointEigenSolver<Mat<3>> solver;
    solver.computeDirect(s, Eigen::EigenvaluesOnly);
    values = solver.eigenvalues();
    if (values[0] < 0 && values[2] > 0) {
      solver.compute(s);
      values = solver.eigenvalues();
      axes = solver.eigenvectors();
    }
  }
  Mat<3> cracked(double factor) const {
    if (values[0] >= 0) return factor * matrix;
    if (values[2] <= 0) return matrix;
    Vec<3> v;
    for (int k = 0; k < 3; ++k) v[k] = crack(values[k], factor);
    return axes * v.asDiagonal() * axes.transpose();
  }
};


}  // namespace outburst::mpm
