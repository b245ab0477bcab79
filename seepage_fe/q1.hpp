#pragma once
// The Q1 elements: the bilinear quadrilateral on the reference square
// [-1, 1]^2 and the trilinear hexahedron on the cube [-1, 1]^3, their
// isoparametric maps, and the element integrals the solver needs. The
// hexahedron's functions overload the quadrilateral's, so code written once
// for both dimensions calls them by the same names.

#include <algorithm>
#include <array>
#include <limits>
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace outburst::seepage::q1 {

using Corners = std::array<Eigen::Vector2d, 4>;

// Reference corner coordinates, counter-clockwise from (-1, -1).
inline constexpr double corner_xi[4] = {-1, 1, 1, -1};
inline constexpr double corner_eta[4] = {-1, -1, 1, 1};

inline std::array<double, 4> shape(double xi, double eta) {
  std::array<double, 4> n{};
  for (int a = 0; a < 4; ++a) n[a] = 0.25 * (1 + corner_xi[a] * xi) * (1 + corner_eta[a] * eta);
  return n;
}

// Shape functions and their x-y gradients at one reference point.
struct Point {
  std::array<double, 4> n;
  std::array<Eigen::Vector2d, 4> grad;
  double det_j;
};

inline Point evaluate(const Corners& x, double xi, double eta) {
  Point p{shape(xi, eta), {}, 0.0};
  std::array<Eigen::Vector2d, 4> dref;
  Eigen::Matrix2d jac = Eigen::Matrix2d::Zero();  // d(x, y) / d(xi, eta)
  for (int a = 0; a < 4; ++a) {
    dref[a] = {0.25 * corner_xi[a] * (1 + corner_eta[a] * eta),
               0.25 * corner_eta[a] * (1 + corner_xi[a] * xi)};
    jac += x[a] * dref[a].transpose();
  }
  p.det_j = jac.determinant();
  const Eigen::Matrix2d inv_t = jac.inverse().transpose();
  for (int a = 0; a < 4; ++a) p.grad[a] = inv_t * dref[a];
  return p;
}

inline Point evaluate(const Corners& x, const Eigen::Vector2d& r) { return evaluate(x, r.x(), r.y()); }

// A nodal field's value and gradient at a point (q1::sample below).
template <int Dim>
struct SampleOf {
  double value;
  Eigen::Matrix<double, Dim, 1> gradient;
};
using Sample = SampleOf<2>;
using Sample3 = SampleOf<3>;

// The same on a parallelogram, whose inverse Jacobian d(xi, eta) / d(x, y) is
// constant and known: no Jacobian to build and invert per point (coupled runs
// sample the pressure at every particle every MPM step). Scalars in and out,
// u(a) the value at corner a and g(r, c) the inverse Jacobian's entries, so
// that SIMD lanes over points (SamplerOf's batches) run the same operations
// in the same order (tests check the numbers are the same).
template <class Corner, class Inverse>
[[gnu::always_inline]] inline void sample_affine(const Corner& u, double xi, double eta, const Inverse& g,
                                                 double& value, double& gradient_x, double& gradient_y) {
  // Scalars throughout: a 2-vector assembled from scalar stores and read
  // back whole stalls the load (no store forwarding) on every sample.
  double sum = 0, along_xi = 0, along_eta = 0;  // u and d u / d(xi, eta)
#pragma GCC unroll 4
  for (int a = 0; a < 4; ++a) {
    const double ua = u(a);
    sum += 0.25 * (1 + corner_xi[a] * xi) * (1 + corner_eta[a] * eta) * ua;
    along_xi += 0.25 * corner_xi[a] * (1 + corner_eta[a] * eta) * ua;
    along_eta += 0.25 * corner_eta[a] * (1 + corner_xi[a] * xi) * ua;
  }
  value = sum;
  // grad u = g^T d u / d(xi, eta)
  gradient_x = g(0, 0) * along_xi + g(1, 0) * along_eta;
  gradient_y = g(0, 1) * along_xi + g(1, 1) * along_eta;
}

template <class Nodal, class Inverse>
Sample sample_affine(const std::array<int, 4>& nodes, const Nodal& u, const Eigen::Vector2d& reference,
                     const Inverse& inverse_jacobian) {
  Sample s;
  sample_affine([&](int a) { return u[nodes[a]]; }, reference.x(), reference.y(), inverse_jacobian, s.value,
                s.gradient.x(), s.gradient.y());
  return s;
}

// 2x2 Gauss rule, exact for the bilinear stiffness on parallelograms.
inline constexpr double gauss2 = 0.57735026918962576451;  // 1/sqrt(3)
inline constexpr std::array<std::array<double, 2>, 4> gauss2_points{
    {{-gauss2, -gauss2}, {gauss2, -gauss2}, {gauss2, gauss2}, {-gauss2, gauss2}}};

struct Integrals {
  Eigen::Matrix4d stiffness;  // int grad N_a . grad N_b dA (unit conductivity)
  Eigen::Vector4d lumped;     // int N_a dA (row sums of the consistent mass)
};

inline Integrals integrals(const Corners& x) {
  Integrals r{Eigen::Matrix4d::Zero(), Eigen::Vector4d::Zero()};
  for (const auto& g : gauss2_points) {
    const Point p = evaluate(x, g[0], g[1]);
    for (int a = 0; a < 4; ++a) {
      r.lumped[a] += p.n[a] * p.det_j;
      for (int b = 0; b < 4; ++b) r.stiffness(a, b) += p.grad[a].dot(p.grad[b]) * p.det_j;
    }
  }
  return r;
}

// Reference coordinates of `point` in the cell, or nullopt if it lies outside
// (with a small tolerance so points on shared edges are found).
inline std::optional<Eigen::Vector2d> inverse_map(const Corners& x, const Eigen::Vector2d& point) {
  // Newton has converged once its step is at the roundoff of the coordinates:
  // about eps |x| in space, eps |x| / (the cell's thinnest side) in reference
  // coordinates. For a small or thin cell far from the origin that lies above
  // any fixed bound (a cell of 1/8 m at x = 40 m: 1.4e-13), and a bound below
  // it missed every point of the cell.
  double reach = 0, thinnest = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 4; ++a) {
    reach = std::max(reach, x[a].lpNorm<Eigen::Infinity>());
    thinnest = std::min(thinnest, (x[(a + 1) % 4] - x[a]).norm());
  }
  const double tolerance = std::max(1e-13, 64 * std::numeric_limits<double>::epsilon() * reach / thinnest);
  Eigen::Vector2d ref = Eigen::Vector2d::Zero();
  bool converged = false;
  for (int it = 0; it < 30; ++it) {
    const auto n = shape(ref.x(), ref.y());
    Eigen::Vector2d mapped = Eigen::Vector2d::Zero();
    Eigen::Matrix2d jac = Eigen::Matrix2d::Zero();
    for (int a = 0; a < 4; ++a) {
      mapped += n[a] * x[a];
      jac += x[a] * Eigen::RowVector2d(0.25 * corner_xi[a] * (1 + corner_eta[a] * ref.y()),
                                        0.25 * corner_eta[a] * (1 + corner_xi[a] * ref.x()));
    }
    const Eigen::Vector2d step = jac.inverse() * (point - mapped);
    ref += step;
    if (step.lpNorm<Eigen::Infinity>() < tolerance) {
      converged = true;
      break;
    }
    if (ref.lpNorm<Eigen::Infinity>() > 10) return std::nullopt;
  }
  // Newton may wander without converging for points outside the cell (the
  // bilinear map need not be invertible there): that is a miss, not a hit.
  if (!converged || ref.lpNorm<Eigen::Infinity>() > 1 + 1e-9) return std::nullopt;
  return ref.cwiseMax(-1.0).cwiseMin(1.0);
}

// ---- the trilinear hexahedron

using Corners3 = std::array<Eigen::Vector3d, 8>;

// Reference corners in Gmsh's order: the face zeta = -1 counter-clockwise
// seen from +zeta, from (-1, -1, -1), then the face zeta = +1 the same way.
inline constexpr double hex_corner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                            {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
// Its six faces, zeta = -1, +1, eta = -1, +1, xi = -1, +1, each by its corners
// counter-clockwise seen from outside.
inline constexpr int hex_face[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                       {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};

inline std::array<double, 8> shape(const Eigen::Vector3d& r) {
  std::array<double, 8> n{};
  for (int a = 0; a < 8; ++a)
    n[a] = 0.125 * (1 + hex_corner[a][0] * r[0]) * (1 + hex_corner[a][1] * r[1]) * (1 + hex_corner[a][2] * r[2]);
  return n;
}

// d N_a / d(xi, eta, zeta).
inline std::array<Eigen::Vector3d, 8> reference_gradients(const Eigen::Vector3d& r) {
  std::array<Eigen::Vector3d, 8> d;
  for (int a = 0; a < 8; ++a) {
    const double f[3] = {1 + hex_corner[a][0] * r[0], 1 + hex_corner[a][1] * r[1], 1 + hex_corner[a][2] * r[2]};
    d[a] = 0.125 * Eigen::Vector3d(hex_corner[a][0] * f[1] * f[2], f[0] * hex_corner[a][1] * f[2],
                                   f[0] * f[1] * hex_corner[a][2]);
  }
  return d;
}

struct Point3 {
  std::array<double, 8> n;
  std::array<Eigen::Vector3d, 8> grad;
  double det_j;
};

inline Point3 evaluate(const Corners3& x, const Eigen::Vector3d& r) {
  Point3 p{shape(r), {}, 0.0};
  const auto dref = reference_gradients(r);
  Eigen::Matrix3d jac = Eigen::Matrix3d::Zero();  // d(x, y, z) / d(xi, eta, zeta)
  for (int a = 0; a < 8; ++a) jac += x[a] * dref[a].transpose();
  p.det_j = jac.determinant();
  const Eigen::Matrix3d inv_t = jac.inverse().transpose();
  for (int a = 0; a < 8; ++a) p.grad[a] = inv_t * dref[a];
  return p;
}

// A nodal field (indexed by node number) and its gradient at a reference
// point of the cell (quadrilateral or hexahedron) with these corners and nodes.
template <class Cell, std::size_t N, class Nodal, class Reference>
SampleOf<Reference::RowsAtCompileTime> sample(const Cell& x, const std::array<int, N>& nodes, const Nodal& u,
                                              const Reference& reference) {
  const auto p = evaluate(x, reference);
  SampleOf<Reference::RowsAtCompileTime> s{0.0, Reference::Zero()};
  for (std::size_t a = 0; a < N; ++a) {
    const double ua = u[nodes[a]];
    s.value += p.n[a] * ua;
    s.gradient += p.grad[a] * ua;
  }
  return s;
}

// The same on a parallelepiped, from its constant inverse Jacobian; scalars
// in and out as on the parallelogram, for SIMD lanes over points.
template <class Corner, class Inverse>
[[gnu::always_inline]] inline void sample_affine(const Corner& u, double xi, double eta, double zeta,
                                                 const Inverse& g, double& value, double& gradient_x,
                                                 double& gradient_y, double& gradient_z) {
  const double r[3] = {xi, eta, zeta};
  double sum = 0, along[3] = {0, 0, 0};  // u and d u / d(xi, eta, zeta)
#pragma GCC unroll 8
  for (int a = 0; a < 8; ++a) {
    const double ua = u(a);
    double f[3];
#pragma GCC unroll 3
    for (int d = 0; d < 3; ++d) f[d] = 1 + hex_corner[a][d] * r[d];
    sum += 0.125 * f[0] * f[1] * f[2] * ua;
    along[0] += 0.125 * (hex_corner[a][0] * f[1] * f[2]) * ua;
    along[1] += 0.125 * (f[0] * hex_corner[a][1] * f[2]) * ua;
    along[2] += 0.125 * (f[0] * f[1] * hex_corner[a][2]) * ua;
  }
  value = sum;
  // grad u = g^T d u / d(xi, eta, zeta)
  const auto column = [&](int c) { return g(0, c) * along[0] + g(1, c) * along[1] + g(2, c) * along[2]; };
  gradient_x = column(0);
  gradient_y = column(1);
  gradient_z = column(2);
}

template <class Nodal, class Inverse>
Sample3 sample_affine(const std::array<int, 8>& nodes, const Nodal& u, const Eigen::Vector3d& reference,
                      const Inverse& inverse_jacobian) {
  Sample3 s;
  sample_affine([&](int a) { return u[nodes[a]]; }, reference.x(), reference.y(), reference.z(), inverse_jacobian,
                s.value, s.gradient.x(), s.gradient.y(), s.gradient.z());
  return s;
}

// 2x2x2 Gauss points, exact for the trilinear stiffness on parallelepipeds.
inline const std::array<Eigen::Vector3d, 8>& gauss2_points3() {
  static const std::array<Eigen::Vector3d, 8> points = [] {
    std::array<Eigen::Vector3d, 8> g;
    for (int a = 0; a < 8; ++a)
      g[a] = gauss2 * Eigen::Vector3d(hex_corner[a][0], hex_corner[a][1], hex_corner[a][2]);
    return g;
  }();
  return points;
}

struct Integrals3 {
  Eigen::Matrix<double, 8, 8> stiffness;  // int grad N_a . grad N_b dV (unit conductivity)
  Eigen::Matrix<double, 8, 1> lumped;     // int N_a dV
};

// Written apart from the quadrilateral's: one template for both moved the
// plane results in their last bits under -march=native (the compiler fused
// other products into FMAs), and the plane runs are kept to the bit.
inline Integrals3 integrals(const Corners3& x) {
  Integrals3 r{Eigen::Matrix<double, 8, 8>::Zero(), Eigen::Matrix<double, 8, 1>::Zero()};
  for (const auto& g : gauss2_points3()) {
    const Point3 p = evaluate(x, g);
    for (int a = 0; a < 8; ++a) {
      r.lumped[a] += p.n[a] * p.det_j;
      for (int b = 0; b < 8; ++b) r.stiffness(a, b) += p.grad[a].dot(p.grad[b]) * p.det_j;
    }
  }
  return r;
}

// Reference coordinates of `point` in the hexahedron, or nullopt outside it;
// the quadrilateral's tolerances, for the same reasons.
inline std::optional<Eigen::Vector3d> inverse_map(const Corners3& x, const Eigen::Vector3d& point) {
  double reach = 0, thinnest = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 8; ++a) reach = std::max(reach, x[a].lpNorm<Eigen::Infinity>());
  for (int a = 0; a < 4; ++a) {  // the twelve edges: around both faces, and between them
    thinnest = std::min({thinnest, (x[(a + 1) % 4] - x[a]).norm(), (x[4 + (a + 1) % 4] - x[4 + a]).norm(),
                         (x[a + 4] - x[a]).norm()});
  }
  const double tolerance = std::max(1e-13, 64 * std::numeric_limits<double>::epsilon() * reach / thinnest);
  Eigen::Vector3d ref = Eigen::Vector3d::Zero();
  bool converged = false;
  for (int it = 0; it < 30; ++it) {
    const auto n = shape(ref);
    const auto dref = reference_gradients(ref);
    Eigen::Vector3d mapped = Eigen::Vector3d::Zero();
    Eigen::Matrix3d jac = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 8; ++a) {
      mapped += n[a] * x[a];
      jac += x[a] * dref[a].transpose();
    }
    const Eigen::Vector3d step = jac.inverse() * (point - mapped);
    ref += step;
    if (step.lpNorm<Eigen::Infinity>() < tolerance) {
      converged = true;
      break;
    }
    if (ref.lpNorm<Eigen::Infinity>() > 10) return std::nullopt;
  }
  if (!converged || ref.lpNorm<Eigen::Infinity>() > 1 + 1e-9) return std::nullopt;
  return ref.cwiseMax(-1.0).cwiseMin(1.0);
}

// ---- both dimensions by one name

// The 2^Dim Gauss points of the 2x2(x2) rule.
template <int Dim>
const std::array<Eigen::Matrix<double, Dim, 1>, (1 << Dim)>& gauss_points() {
  if constexpr (Dim == 2) {
    static const std::array<Eigen::Vector2d, 4> points{
        Eigen::Vector2d(gauss2_points[0][0], gauss2_points[0][1]), Eigen::Vector2d(gauss2_points[1][0], gauss2_points[1][1]),
        Eigen::Vector2d(gauss2_points[2][0], gauss2_points[2][1]), Eigen::Vector2d(gauss2_points[3][0], gauss2_points[3][1])};
    return points;
  } else {
    return gauss2_points3();
  }
}

// ---- boundary faces: int N_a dS of each corner of a face

// An edge (2D): half its length at each end.
inline std::array<double, 2> face_lumped(const std::array<Eigen::Vector2d, 2>& x) {
  const double half = 0.5 * (x[1] - x[0]).norm();
  return {half, half};
}

// A bilinear quadrilateral in space (3D), by 2x2 Gauss points.
inline std::array<double, 4> face_lumped(const std::array<Eigen::Vector3d, 4>& x) {
  std::array<double, 4> w{};
  for (const auto& g : gauss2_points) {
    Eigen::Vector3d along_xi = Eigen::Vector3d::Zero(), along_eta = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) {
      along_xi += 0.25 * corner_xi[a] * (1 + corner_eta[a] * g[1]) * x[a];
      along_eta += 0.25 * corner_eta[a] * (1 + corner_xi[a] * g[0]) * x[a];
    }
    const double area = along_xi.cross(along_eta).norm();
    const auto n = shape(g[0], g[1]);
    for (int a = 0; a < 4; ++a) w[a] += n[a] * area;
  }
  return w;
}

}  // namespace outburst::seepage::q1
