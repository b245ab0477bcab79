#pragma once
// What the seepage solver solves: the storage law, materials per region,
// boundary conditions, and the numerical settings. All values SI.
//
// Both laws are one conservation equation for a nodal unknown u,
//
//     d/dt [ c X(u) ] = div( k grad u ) + s,
//
// gas law (paper eqs. 1-5, model-notes section 1):
//     u = P = p^2 [Pa^2], X = P^(1/4) = sqrt(p), c = A [Pa^-1/2],
//     k = lambda [m^2/(Pa^2 s)]; expanding d/dt gives (A/4) P^(-3/4) dP/dt.
//     Stored gas c X is a standard gas volume per unit coal volume.
// linear Darcy law (classical verification, consolidation):
//     u = p [Pa], X = p, c = S [1/Pa] (storage coefficient), k = k/mu [m^2/(Pa s)].
// Solving the conservative form d(cX)/dt, not c X'(u) du/dt, makes the discrete
// gas balance exact: stored gas plus what crossed the boundary is constant.

#include <cmath>
#include <string>
#include <vector>

#include "common/time_function.hpp"

namespace outburst::seepage {

enum class Law { gas, linear };

inline double storage_x(Law law, double u) { return law == Law::gas ? std::sqrt(std::sqrt(u)) : u; }
inline double storage_dx(Law law, double u) {
  return law == Law::gas ? 0.25 * std::sqrt(std::sqrt(u)) / u : 1.0;
}
// The nodal unknown for a pressure p, and back.
inline double unknown_from_pressure(Law law, double p) { return law == Law::gas ? p * p : p; }
inline double pressure_from_unknown(Law law, double u) {
  return law == Law::gas ? std::sqrt(std::max(u, 0.0)) : u;
}

struct Material {
  double conductivity;      // lambda (gas) or k/mu (linear)
  double capacity;          // A (gas) or S (linear)
  double initial_pressure;  // p at t = 0 [Pa]
};

struct BoundaryCondition {
  enum class Type { pressure, flux };
  std::string boundary;  // a mesh boundary name
  Type type;
  // pressure: p [Pa]; flux: inflow per unit boundary area (2D: per unit
  // length and depth) [m/s] (standard gas volume for the gas law), positive
  // into the domain.
  TimeFunction value;
};

struct Model {
  Law law = Law::gas;
  std::vector<Material> materials;  // one per mesh region
  std::vector<BoundaryCondition> boundary_conditions;  // unlisted boundaries: no flow
};

enum class TimeScheme { backward_euler, bdf2 };
enum class NonlinearMethod { newton, picard };
enum class LinearSolver { direct, cg, lagged };
// How tightly conjugate gradients solve each Newton system: every one to
// cg_tolerance, or by Eisenstat and Walker's forcing term (their choice 2,
// SIAM J. Sci. Comput. 17, 1996): loosely while Newton is far from the
// solution, to cg_tolerance as it converges.
enum class Forcing { fixed, adaptive };

struct Settings {
  TimeScheme scheme = TimeScheme::bdf2;
  NonlinearMethod method = NonlinearMethod::newton;
  double tolerance = 1e-10;  // on the relative update max|du| / max|u|
  int max_iterations = 30;
  int max_step_cuts = 12;    // halvings of a failing step before giving up
  // The Newton systems: CHOLMOD; conjugate gradients preconditioned by an
  // incomplete Cholesky factor; or (lagged) conjugate gradients preconditioned
  // by CHOLMOD's factor of an earlier Jacobian, renewed at the next iteration
  // once they use more than half of lag_max_iterations, and at once (solving
  // directly) when they do not converge within it. Both iterative ones solve
  // to ||J du + r|| <= cg_tolerance ||r||. The linear law's Jacobian does not
  // move: lagged solves it as direct does.
  LinearSolver linear_solver = LinearSolver::direct;
  double cg_tolerance = 1e-8;
  Forcing cg_forcing = Forcing::fixed;
  int cg_max_iterations = 5000;  // beyond them the step is cut
  int lag_max_iterations = 10;
};

}  // namespace outburst::seepage
