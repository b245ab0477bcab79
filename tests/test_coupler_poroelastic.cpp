// Poroelastic checks of the coupling with the Biot storage term: Terzaghi's
// consolidation (cases/terzaghi) against the analytic series.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

#include "coupler/model.hpp"

using namespace outburst;

namespace {

// Terzaghi: p(z, t) = sum 2 p0 / M_m sin(M_m z / H) exp(-M_m^2 T), z from the
// drained top, M_m = pi (2m + 1) / 2, T = c_v t / H^2; the settlement goes
// from the undrained u0 to the drained u_inf as 1 - sum 2 / M_m^2 exp(-M_m^2 T).
struct Terzaghi {
  double H, p0, cv, u0, u_inf;
  double pressure(double z, double t) const {
    double sum = 0;
    for (int m = 0; m < 400; ++m) {
      const double mm = 3.14159265358979323846 * (2 * m + 1) / 2;
      sum += 2 * p0 / mm * std::sin(mm * z / H) * std::exp(-mm * mm * cv * t / (H * H));
    }
    return sum;
  }
  double settlement(double t) const {
    double sum = 0;
    for (int m = 0; m < 400; ++m) {
      const double mm = 3.14159265358979323846 * (2 * m + 1) / 2;
      sum += 2 / (mm * mm) * std::exp(-mm * mm * cv * t / (H * H));
    }
    return u0 + (u_inf - u0) * (1 - sum);
  }
};

}  // namespace

TEST_CASE("Terzaghi consolidation: pore pressure and settlement follow the analytic series",
          "[coupler][poroelastic][terzaghi]") {
  auto doc = scene::Document::load(std::string(OUTBURST_SOURCE_DIR) + "/cases/terzaghi/terzaghi.toml");
  coupling::CoupledModel model(coupling::read_coupled_setup(doc->root()));
  doc->reject_unused();
  // The scene's values (see its header): M = E (1 - nu) / ((1 + nu)(1 - 2 nu)).
  const double e = 1e7, nu = 0.25, q = 1e4, s = 1e-7, k_mu = 1.833e-10 / 1e-3, alpha = 1.0, height = 1.0;
  const double m = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const Terzaghi exact{height, alpha * q / (alpha * alpha + s * m), k_mu / (s + alpha * alpha / m),
                       q * height / (m + alpha * alpha / s), q * height / m};
  const auto& mesh = model.mapping().mesh();
  double worst = 0;
  for (double t_check : {0.1, 0.2, 0.3, 0.4, 0.5}) {
    while (model.coupling().time() < t_check - 1e-12) model.advance(t_check);
    const auto p = model.seepage().nodal_pressure();
    double sum2 = 0;
    for (std::size_t i = 0; i < mesh.num_nodes(); ++i)
      sum2 += std::pow(p[i] - exact.pressure(height - mesh.nodes[i].y(), t_check), 2);
    const double rms = std::sqrt(sum2 / static_cast<double>(mesh.num_nodes())) / exact.p0;
    // Settlement: the mean displacement of the top row of particles.
    const auto& particles = model.solid().particles();
    double top = 0, count = 0;
    for (std::size_t i = 0; i < particles.size(); ++i)
      if (particles.x0[i].y() > height - 0.05) {
        top += particles.x0[i].y() - particles.x[i].y();
        ++count;
      }
    top /= count;
    std::printf("t = %.1f s: pressure RMS error %.4f p0, settlement %.4e m (exact %.4e, %+.2f%%)\n", t_check, rms,
                top, exact.settlement(t_check), 100 * (top / exact.settlement(t_check) - 1));
    worst = std::max(worst, rms);
    CHECK(rms < 0.03);
    CHECK(top == Approx(exact.settlement(t_check)).epsilon(0.06));
  }
  std::printf("worst pressure RMS error %.4f p0 (explicit staggered, window 5 ms)\n", worst);
}
