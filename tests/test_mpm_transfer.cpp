// Velocity transfers: APIC keeps the angular momentum of a spinning disk, PIC
// loses it to the grid. (Measured on x_p x m_p v_p alone; APIC's exact invariant
// also counts each particle's affine part, hence the 1e-6 left.)
#include <catch2/catch.hpp>

#include <cmath>

#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

// Angular momentum about the disk's centre after `steps` steps of a disk spinning
// at omega, relative to its initial value.
double spin_kept(ShapeKind shape, bool apic, double flip, int steps) {
  const Grid<2> gr = grid(1.0, 1.0, 0.05);
  const Vec<2> centre(0.5, 0.5);
  const double omega = 1.0, radius = 0.3;
  std::vector<Vec<2>> points;
  fill_cells<2>(gr, 2, centre.array() - radius, centre.array() + radius,
             [&](const Vec<2>& x) { return (x - centre).norm() <= radius; }, points);
  Particles<2> p;
  const double volume = 0.025 * 0.025;
  for (const auto& x : points) {
    const Vec<2> r = x - centre;
    p.add(x, omega * Vec<2>(-r.y(), r.x()), 1000 * volume, volume, 0.25, Mat<2>::Zero(), 0, 0);
    if (apic) {
      p.need_affine();
      p.affine.back() << 0, -omega, omega, 0;  // the rigid rotation's velocity gradient
    }
  }
  Settings<2> s;
  s.shape = shape;
  s.apic = apic;
  s.flip_fraction = flip;
  Solver<2> solver(gr, elastic({1000, 1e6, 0.3}), std::move(p), s);
  const auto angular = [&] {
    double l = 0;
    const auto& q = solver.particles();
    for (std::size_t i = 0; i < q.size(); ++i) {
      const Vec<2> r = q.x[i] - centre;
      l += q.mass[i] * (r.x() * q.v[i].y() - r.y() * q.v[i].x());
    }
    return l;
  };
  const double l0 = angular();
  const double dt = solver.stable_time_step();
  for (int i = 0; i < steps; ++i) solver.step(dt);
  return angular() / l0;
}

}  // namespace

TEST_CASE("APIC conserves angular momentum where PIC dissipates it", "[mpm][transfer]") {
  for (auto shape : {ShapeKind::bspline, ShapeKind::gimp, ShapeKind::linear}) {
    const double apic = spin_kept(shape, true, 0, 400);
    const double pic = spin_kept(shape, false, 0.0, 400);
    std::printf("\nspinning disk, shape %d, after 400 steps: angular momentum kept APIC %.12f, PIC %.6f\n",
                int(shape), apic, pic);
    CHECK(apic == Approx(1.0).epsilon(1e-5));
    CHECK(pic < 0.5);
  }
}

// A transfer's own fields exist only in runs whose transfer uses them: USF's
// fused FLIP pass keeps the velocity gradients in SIMD lanes and needs no B.
TEST_CASE("the velocity gradients and APIC's B are particle fields only where the transfer uses them",
          "[mpm][transfer][particles]") {
  struct Run {
    Scheme scheme;
    bool apic, smooth, gradients, affine;
  };
  for (const Run r : {Run{Scheme::usf, false, false, false, false}, Run{Scheme::usf, true, false, false, true},
                      Run{Scheme::usf, false, true, true, false}, Run{Scheme::usl, false, false, true, false},
                      Run{Scheme::musl, true, false, true, true}}) {
    const Grid<2> g = grid(1.0, 1.0, 0.1);
    Settings<2> s;
    s.scheme = r.scheme;
    s.apic = r.apic;
    s.smooth_dilatation = r.smooth;
    s.gravity = Vec<2>(0, -9.81);
    Solver<2> solver(g, elastic({1000, 1e6, 0.3}), block(g, Vec<2>(0.2, 0.2), Vec<2>(0.6, 0.5), 1000, 2), s);
    INFO("scheme " << int(r.scheme) << ", APIC " << r.apic << ", smoothed dilatation " << r.smooth);
    const auto& p = solver.particles();
    CHECK(p.velocity_gradient.size() == (r.gradients ? p.size() : 0));
    CHECK(p.affine.size() == (r.affine ? p.size() : 0));
    for (int k = 0; k < 20; ++k) solver.step(solver.stable_time_step());
    CHECK(p.velocity_gradient.size() == (r.gradients ? p.size() : 0));
    // The block has fallen: a stored gradient is the last step's, not zero.
    if (r.gradients) CHECK(p.velocity_gradient[0].norm() > 0);
  }
}
