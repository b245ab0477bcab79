// The stability analysis of the poroelastic window schemes (coupler/stability.hpp):
// its amplification against a brute-force integration of one mode, the end
// pressure's unconditional stability, and the scene-level choice and refusal.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "coupler/model.hpp"
#include "coupler/stability.hpp"

using namespace outburst;
using namespace outburst::coupling::stability;

namespace {

// Terzaghi's column (cases/terzaghi) at a given fluid stiffness S M.
Regime column(double sm, double biot = 1.0, double damping = 400) {
  const double e = 10e6, nu = 0.25;
  const double lambda = e * nu / ((1 + nu) * (1 - 2 * nu)), shear = e / (2 * (1 + nu));
  const double m = lambda + 2 * shear;
  return {1000, m, lambda + 2.0 / 3.0 * shear, damping, biot, sm / m, 1.833e-7, 1.0, 0.05};
}

// One mode through `windows` windows of the scheme, the solid by RK4 in 400
// steps a window, the fluid by backward Euler; the converged windows solved
// for p_n+1 by the secant through two trial values (the window is linear in
// it). Returns the growth rate of |(eps, p / M_c)|, the least-squares slope
// of its logarithm over the second half of the windows (a mode that rotates
// from eps to v and back needs many periods to show its rate).
double brute_force(const Regime& g, const Window& w, double kappa, int windows) {
  const double lambda_h = 4 / (g.cell * g.cell) * std::pow(std::sin(0.5 * kappa * g.cell), 2);
  const double beta = w.fixed_stress ? g.biot * g.biot / g.bulk_modulus : 0.0;
  struct State {
    double eps, v;
  };
  // The solid over a window feeling q(t) = q0 + (q1 - q0) t / window.
  const auto solid = [&](State s, double q0, double q1) {
    const int n = 400;
    const double dt = w.size / n;
    const auto rate = [&](double t, const State& y) {
      const double q = q0 + (q1 - q0) * t / w.size;
      return State{y.v, -g.damping * y.v - kappa * kappa / g.density * (g.p_wave_modulus * y.eps - g.biot * q)};
    };
    for (int i = 0; i < n; ++i) {
      const double t = i * dt;
      const State k1 = rate(t, s);
      const State k2 = rate(t + dt / 2, {s.eps + dt / 2 * k1.eps, s.v + dt / 2 * k1.v});
      const State k3 = rate(t + dt / 2, {s.eps + dt / 2 * k2.eps, s.v + dt / 2 * k2.v});
      const State k4 = rate(t + dt, {s.eps + dt * k3.eps, s.v + dt * k3.v});
      s.eps += dt / 6 * (k1.eps + 2 * k2.eps + 2 * k3.eps + k4.eps);
      s.v += dt / 6 * (k1.v + 2 * k2.v + 2 * k3.v + k4.v);
    }
    return s;
  };
  const auto felt = [&](double p, double p1) { return w.pressure == Pressure::ramp ? p : p1; };
  State s{1e-6, 0};
  double p = 0, eps_prev = s.eps, p_prev = 0;
  std::vector<double> log_size;  // the state is rescaled to size 1 after each window
  for (int k = 0; k < windows; ++k) {
    double p1;
    if (w.iterated) {
      // S (p1 - p) + alpha (eps1(p1) - eps) + drain p1 = 0, linear in p1.
      const auto residual = [&](double trial) {
        const State end = solid(s, felt(p, trial), trial);
        return g.storage * (trial - p) + g.biot * (end.eps - s.eps) + g.mobility * lambda_h * w.size * trial;
      };
      const double r0 = residual(0), r1 = residual(1);
      p1 = -r0 / (r1 - r0);
    } else {
      p1 = ((g.storage + beta) * p - g.biot * (s.eps - eps_prev) + beta * (p - p_prev)) /
           (g.storage + beta + g.mobility * lambda_h * w.size);
    }
    eps_prev = s.eps;
    p_prev = p;
    s = solid(s, felt(p, p1), p1);
    p = p1;
    const double size = std::hypot(s.eps, p / g.p_wave_modulus);
    log_size.push_back((log_size.empty() ? 0.0 : log_size.back()) + std::log(size));
    for (double* x : {&s.eps, &s.v, &p, &eps_prev, &p_prev}) *x /= size;
  }
  double st = 0, sy = 0, stt = 0, sty = 0, n = 0;
  for (std::size_t k = log_size.size() / 2; k < log_size.size(); ++k, ++n) {
    const double t = static_cast<double>(k) * w.size;
    st += t;
    sy += log_size[k];
    stt += t * t;
    sty += t * log_size[k];
  }
  return (n * sty - st * sy) / (n * stt - st * st);
}

}  // namespace

TEST_CASE("the window schemes' amplification matches a brute-force integration of one mode",
          "[coupler][stability]") {
  struct Case {
    const char* label;
    Regime regime;
    Window window;
    int mode;
  };
  const std::vector<Case> cases{
      {"implicit ramp, S M 0.01, 5 ms, first mode", column(0.01), {true, false, Pressure::ramp, 5e-3}, 1},
      {"implicit ramp, S M 0.1, 1.25 ms, sixth mode", column(0.1), {true, false, Pressure::ramp, 1.25e-3}, 6},
      {"implicit end, S M 0.01, 1.25 ms, sixth mode", column(0.01), {true, false, Pressure::end, 1.25e-3}, 6},
      {"explicit ramp, S M 1.2, 2.5 ms, second mode", column(1.2), {false, false, Pressure::ramp, 2.5e-3}, 2},
      {"explicit fixed stress, S M 0.01, 1.25 ms, 4th mode", column(0.01), {false, true, Pressure::ramp, 1.25e-3}, 4},
  };
  std::printf("\none mode: growth rate [1/s], analysis against brute force\n");
  for (const auto& c : cases) {
    const double kappa = (c.mode - 0.5) * std::numbers::pi / c.regime.length;
    const double predicted = std::log(amplification(c.regime, c.window, kappa)) / c.window.size;
    const double integrated = brute_force(c.regime, c.window, kappa, 400);
    std::printf("  %-52s %9.2f %9.2f\n", c.label, predicted, integrated);
    INFO(c.label);
    CHECK(predicted == Approx(integrated).epsilon(0.02).margin(0.1));
  }
}

TEST_CASE("iterated with the end pressure, no mode grows for any window, fluid stiffness or Biot coefficient",
          "[coupler][stability]") {
  double largest = 0;
  for (double sm : {10.0, 1.2, 0.1, 0.01, 1e-3, 1e-4})
    for (double window : {4e-2, 1e-2, 2.5e-3, 6.25e-4, 1e-4})
      for (double biot : {0.2, 0.5, 1.0})
        for (double damping : {0.0, 400.0}) {
          const Regime g = column(sm, biot, damping);
          for (double kappa : wavenumbers(g))
            largest = std::max(largest, amplification(g, {true, false, Pressure::end, window}, kappa));
        }
  std::printf("\nend pressure, iterated: largest amplification over 3600 modes and regimes %.12f\n", largest);
  CHECK(largest <= 1 + 1e-9);
  // The ramp is not: the nearly incompressible column at a 5 ms window.
  CHECK(growth(column(0.01), {true, false, Pressure::ramp, 5e-3}).rate > 50);
}

namespace {

std::unique_ptr<scene::Document> terzaghi(std::vector<std::string> overrides) {
  return scene::Document::load(std::string(OUTBURST_SOURCE_DIR) + "/cases/terzaghi/terzaghi.toml", overrides);
}

const std::string stiff_fluid = "seepage.regions[0].storage_coefficient=\"8.333e-10 Pa^-1\"";  // S M = 0.01

}  // namespace

TEST_CASE("a scheme predicted unstable is replaced (auto) or refused before the first step, naming the stable one",
          "[coupler][stability]") {
  // Auto: the ramp is predicted to grow, so the end pressure (and the
  // fixed-stress split) is chosen.
  auto doc = terzaghi({stiff_fluid});
  const auto setup = coupling::read_coupled_setup<2>(doc->root());
  CHECK(setup.coupling.window_pressure == Pressure::end);
  CHECK(setup.coupling.fixed_stress_split == true);
  // The scene's own regime keeps the ramp.
  auto plain = terzaghi({});
  CHECK(coupling::read_coupled_setup<2>(plain->root()).coupling.window_pressure == Pressure::ramp);
  // Named explicitly, the ramp is refused, with the alternative.
  auto ramp = terzaghi({stiff_fluid, "coupling.window_pressure=\"ramp\""});
  REQUIRE_THROWS_AS(coupling::read_coupled_setup<2>(ramp->root()), scene::Refusal);
  try {
    coupling::read_coupled_setup<2>(ramp->root());
  } catch (const scene::Refusal& e) {
    const std::string message = e.what();
    CHECK_THAT(message, Catch::Contains("coupling.window_pressure") && Catch::Contains("grows by 76") &&
                            Catch::Contains("window_pressure = \"end\""));
  }
  // So is a one-pass scheme no window pressure saves.
  auto explicit_scheme = terzaghi({"coupling.scheme=\"explicit\"", "coupling.window=\"2.5 ms\""});
  CHECK_THROWS_AS(coupling::read_coupled_setup<2>(explicit_scheme->root()), scene::Refusal);
  // Unless asked to run it anyway (to measure it).
  auto allowed = terzaghi({"coupling.scheme=\"explicit\"", "coupling.window=\"2.5 ms\"", "coupling.allow_unstable=true"});
  CHECK_NOTHROW(coupling::read_coupled_setup<2>(allowed->root()));
}

TEST_CASE("the predicted growth of the ramp is the growth a Terzaghi run with a nearly incompressible fluid shows",
          "[coupler][stability]") {
  auto doc = terzaghi({stiff_fluid, "coupling.window_pressure=\"ramp\"", "coupling.allow_unstable=true",
                       "scene.end_time=\"0.07 s\""});
  auto setup = coupling::read_coupled_setup<2>(doc->root());
  double predicted = -1e300;
  for (const auto& r : coupling::poroelastic_regimes(setup))
    predicted = std::max(predicted, growth(r, {true, false, Pressure::ramp, setup.coupling.window}).rate);
  coupling::CoupledModel model(std::move(setup));
  std::vector<double> t, kinetic;
  while (model.coupling().time() < 0.07 - 1e-12) {
    model.advance(0.07);
    t.push_back(model.coupling().time());
    kinetic.push_back(model.solid().kinetic_energy());
  }
  // The kinetic energy over the last 0.03 s, halved: an amplitude's rate.
  const std::size_t from = t.size() - 6;
  const double measured = 0.5 * std::log(kinetic.back() / kinetic[from]) / (t.back() - t[from]);
  std::printf("\nTerzaghi, S M = 0.01, 5 ms windows, ramp: growth predicted %.1f 1/s, measured %.1f 1/s\n", predicted,
              measured);
  CHECK(measured == Approx(predicted).epsilon(0.1));
}

TEST_CASE("a fixed MPM time step in a coupled scene is checked against the stable step before the first step",
          "[coupler][stability]") {
  // Terzaghi's column: P wave 110 m/s on 0.05 m cells, a stable step of 4.5e-4 s at Courant 1.
  auto ok = terzaghi({"mpm.time_step=\"1e-4 s\""});
  CHECK_NOTHROW(coupling::read_coupled_setup<2>(ok->root()));
  auto too_long = terzaghi({"mpm.time_step=\"1e-3 s\""});
  try {
    coupling::read_coupled_setup<2>(too_long->root());
    FAIL("a step above the stable one was accepted");
  } catch (const scene::Error& e) {
    const std::string message = e.what();
    CHECK_THAT(message, Catch::Contains("mpm.time_step") && Catch::Contains("exceeds the stability limit"));
  }
}
