#pragma once
// Stability of the poroelastic window schemes (Biot storage coupling): the
// amplification of one window per wavenumber; docs/theory/coupling.md#7-stability-of-the-window-schemes
// derives it.
//
// The model is one Fourier mode of a uniaxial column, wavenumber kappa:
//   solid:  rho (eps'' + c eps') = -kappa^2 (M_c eps - alpha p)
//   fluid:  S p' + alpha eps' = -(k/mu) lambda_h p
// eps the volumetric strain, M_c the drained P-wave modulus, c the viscous
// damping, lambda_h = (4 / h^2) sin^2(kappa h / 2) the Q1 (lumped) seepage
// mesh's eigenvalue of -d2/dx2. The solid is integrated exactly over the
// window (its explicit steps are far shorter); the fluid takes one backward
// Euler step per window, as the seepage does. Schemes differ in
//   - the pressure the solid feels within the window: the ramp from p_n to
//     p_n+1, or p_n+1 held over the whole window (backward Euler in the
//     coupling);
//   - iterated to convergence (the implicit scheme, whatever its
//     acceleration; the fixed-stress terms cancel at convergence), or one
//     pass, in which the fluid sees the solid's volume change of the last
//     window (with the fixed-stress split: and the extra storage
//     beta = alpha^2 / K_dr with its lagged source).
// Iterated with the end pressure, the discrete energy
//   rho v^2 / kappa^2 + M_c eps^2 + S p^2
// never grows (its change is -damping -drainage -S (p_n+1 - p_n)^2), so that
// scheme is stable for any window and any fluid stiffness; the others are
// not (a fast-oscillating solid's response to the ramp lags p_n+1).

#include <vector>

namespace outburst::coupling::stability {

enum class Pressure { ramp, end };

struct Window {
  bool iterated = true;       // sub-iterations to convergence (implicit) or one pass (explicit)
  bool fixed_stress = false;  // the seepage's fixed-stress split (matters in one pass only)
  Pressure pressure = Pressure::ramp;
  double size = 0;  // [s]
};

// One pair of solid material and seepage region.
struct Regime {
  double density = 0;         // rho [kg/m3]
  double p_wave_modulus = 0;  // M_c = lambda + 2 G, drained [Pa]
  double bulk_modulus = 0;    // K_dr (fixed-stress storage alpha^2 / K_dr) [Pa]
  double damping = 0;         // mass-proportional viscous damping c [1/s]
  double biot = 0;            // alpha
  double storage = 0;         // S [1/Pa]
  double mobility = 0;        // k / mu [m2/(Pa s)]
  double length = 0;          // extent the modes span [m]
  double cell = 0;            // seepage cell size [m]
};

// The modes the seepage mesh carries: kappa_j = (j - 1/2) pi / length,
// j = 1 .. length / cell (a column drained at one end).
std::vector<double> wavenumbers(const Regime& regime);

// Spectral radius of one window's amplification matrix for one mode.
double amplification(const Regime& regime, const Window& window, double wavenumber);

// The largest growth rate over the mesh's modes, ln(radius) / window [1/s]:
// negative when every mode decays (then it is the slowest mode's decay rate).
struct Growth {
  double rate = 0;        // [1/s]
  double wavenumber = 0;  // of the fastest-growing (or slowest-decaying) mode [1/m]
};
Growth growth(const Regime& regime, const Window& window);

// The first window from `from` [s] up, in steps of 2^(1/8), that the scheme
// keeps stable (growth rate <= 0), searched up to `up_to`; 0 if none is.
double smallest_stable_window(const Regime& regime, Window window, double from, double up_to);

}  // namespace outburst::coupling::stability
