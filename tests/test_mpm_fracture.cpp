// Fracture with a length scale (issue 17). A bar pulled past its peak by a
// plate moved at a set speed: with a fracture energy (the crack band, as wide
// as the shape functions spread a crack: crack_cells in mpm_solid/solver.hpp)
// it dissipates G_f per unit crack area at every resolution under every shape
// function, and its load-displacement curves coincide (with a cohesive
// crack's under linear and GIMP shapes); under the paper's local law the
// dissipation shrinks with the cell. A notched beam in bending: the crack
// band's peak and softening agree as the cells halve, the local law's do not.
// Nonlocal damage in a necked bar: the energy and the curve converge as the
// cells shrink under a fixed internal length.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "mpm_fixtures.hpp"
#include "mpm_solid/materials/elastic_damage.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

// Coal (Table 1) with a fracture energy K_Ic^2 / E of outburst-prone coal
// (K_Ic = 0.12 MPa m^0.5), and nu = 0.25 for a quicker test.
const Elasticity coal{1600, 6e9, 0.25};
constexpr double strength = 0.2e6, fracture_energy = 0.12e6 * 0.12e6 / 6e9;
// The bar is shorter than 2 E G_f / f_t^2 (0.72 m): longer, the elastic energy
// it releases as the band softens would break it at once (a snap-back).
constexpr double length = 0.25, height = 0.05, speed = 0.01;  // [m], [m], [m/s]
// The band where the bar breaks is 5 % weaker, so that it breaks there; the
// grips, three cells at each end, twice as strong, so that it does not break
// where the plate and the wall meet it (as a dog-bone specimen).
constexpr double weak = 0.95, grip = 2.0;

// Plate displacements at which curves are compared: to twice the opening at
// which the cohesive crack carries nothing.
constexpr int samples = 400;
constexpr double end = 2 * (2 * fracture_energy / (weak * strength));

// A load-displacement curve sampled at u = span k / samples, linearly
// between the steps' (u, force).
struct Curve {
  explicit Curve(double span) : span(span) {}
  double span;
  std::vector<double> force;
  double last_u = 0, last_force = 0;
  void add(double u, double f) {
    for (; static_cast<int>(force.size()) < samples && span * force.size() / samples <= u;) {
      const double at = span * force.size() / samples;
      force.push_back(last_force + (f - last_force) * (at - last_u) / (u - last_u));
    }
    last_u = u;
    last_force = f;
  }
};

struct Pull {
  double dissipated_per_area = 0;  // by damage, over the crack area [J/m2]
  double peak_force = 0;           // [N/m]
  std::vector<double> force;       // [N/m] at u = (the plate's travel) k / samples
};

// The running mean of f over 2 half + 1 samples (where it has them all).
double running_mean(const std::vector<double>& f, int k, int half) {
  double sum = 0;
  for (int j = k - half; j <= k + half; ++j) sum += f[j];
  return sum / (2 * half + 1);
}

// Mean |a - b| over the mean |b| of two sampled curves, each first averaged
// over 2 half + 1 samples, about a period of the ringing of the explicit
// steps (each grid rings about a common curve in its own phase).
double distance(const std::vector<double>& a, const std::vector<double>& b, int half) {
  double gap = 0, size = 0;
  for (int k = half; k < static_cast<int>(a.size()) - half; ++k) {
    gap += std::abs(running_mean(a, k, half) - running_mean(b, k, half));
    size += std::abs(running_mean(b, k, half));
  }
  return gap / size;
}

// The bar rings at period 2 L / c: half of it in samples of a plate's travel
// to `to`.
int bar_ringing(double to = end) {
  const double period = 2 * length / std::sqrt(coal.youngs_modulus / coal.density) * speed;
  return static_cast<int>(0.5 * period / (to / samples));
}

// Plate force of a cohesive crack with linear softening in the bar [N/m] at
// plate displacement u: elastic up to the weak band's strength, then the crack
// opens by 2 G_f / f_t (1 - sigma / f_t) while the bar unloads (plane strain,
// free sides: E / (1 - nu^2)).
double cohesive_force(double u) {
  const double e = coal.youngs_modulus / (1 - coal.poisson_ratio * coal.poisson_ratio);
  const double ft = weak * strength, opening = 2 * fracture_energy / ft;
  const double peak_u = ft * length / e;
  if (u <= peak_u) return e * u / length * height;
  // u = sigma L / E' + w_c (1 - sigma / f_t), solved for sigma.
  const double sigma = (u - opening) / (length / e - opening / ft);
  return std::max(sigma, 0.0) * height;
}

// The bar's grid and boundaries: [0, length] x [0, height] on rollers at
// x = 0 and y = 0 (a symmetric half), pulled at x = length by a plate.
Settings<2> bar_settings(double h, ShapeKind shape) {
  Settings<2> s;
  s.shape = shape;
  s.walls = {Wall{Wall::Type::roller}, Wall{}, Wall{Wall::Type::roller}, Wall{}};
  s.platens.push_back({Vec<2>(length - 0.25 * h, -1), Vec<2>(length + 3 * h, 1), 0, 0, speed});
  return s;
}

// Pulls the bar until the plate has moved `to`; the crack is `ligament` high.
Pull pull_until(double h, const Settings<2>& s, std::vector<std::unique_ptr<Material<2>>> materials,
                Particles<2> particles, double to, double ligament) {
  Solver<2> solver(grid(length + 3 * h, height, h), std::move(materials), std::move(particles), s);
  Pull r;
  Curve curve(to);
  while (solver.platen_displacement()[0] < to) {
    solver.step(solver.stable_time_step());
    r.peak_force = std::max(r.peak_force, solver.platen_force()[0]);
    curve.add(solver.platen_displacement()[0], solver.platen_force()[0]);
  }
  r.force = std::move(curve.force);
  r.dissipated_per_area = solver.energies().damage / ligament;
  return r;
}

// The bar pulled apart; h the cell, `local` the paper's law with eta = 5
// instead of the crack band.
Pull pull(double h, ShapeKind shape, bool local) {
  auto particles = block(grid(length + 3 * h, height, h), {0, 0}, {length, height}, coal.density, 2);
  const double band = 0.5 * length;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double x = particles.x[i].x();
    particles.material[i] = x > band && x < band + h ? 1 : x < 3 * h || x > length - 3 * h ? 2 : 0;
    // Already stretching as the plate will stretch it: no wave at the start.
    particles.v[i].x() = speed * x / length;
  }
  std::vector<std::unique_ptr<Material<2>>> materials;
  for (double share : {1.0, weak, grip}) {
    DamageParameters d{1e6, 0.5, share * strength, 0.3, 5.0, std::nullopt};
    if (!local) {
      d.fracture_energy = fracture_energy;
      d.band_width = crack_cells(shape) * h;
    }
    materials.push_back(std::make_unique<ElasticDamage<2>>("coal", coal, d));
  }
  return pull_until(h, bar_settings(h, shape), std::move(materials), std::move(particles), end, height);
}

}  // namespace

TEST_CASE("crack band: a bar pulled apart dissipates G_f per crack area at every resolution and shape",
          "[mpm][fracture]") {
  std::printf("\nbar pulled apart, G_f = %.3f J/m2; load-displacement curves' distance from the cohesive crack's "
              "and from the finest run's\n%8s %8s %16s %16s %16s %12s\n",
              fracture_energy, "shape", "cell [m]", "dissipated / G_f", "from cohesive", "from finest", "peak [kN/m]");
  const char* names[] = {"linear", "gimp", "bspline"};
  std::vector<double> cohesive;
  for (int k = 0; k < samples; ++k) cohesive.push_back(cohesive_force(end * k / samples));
  const double impedance = std::sqrt(coal.youngs_modulus * coal.density);
  for (ShapeKind shape : {ShapeKind::linear, ShapeKind::gimp, ShapeKind::bspline}) {
    std::vector<Pull> pulls;
    for (double h : {0.003125, 0.00625, 0.0125, 0.025}) {
      const Pull& b = pulls.emplace_back(pull(h, shape, false));
      std::printf("%8s %8.4f %16.4f %16.4f %16.4f %12.3f\n", names[static_cast<int>(shape)], h,
                  b.dissipated_per_area / fracture_energy, distance(b.force, cohesive, bar_ringing()),
                  distance(b.force, pulls.front().force, bar_ringing()), b.peak_force / 1e3);
      CHECK(b.dissipated_per_area == Approx(fracture_energy).epsilon(0.02));
      // The curves coincide with the finest run's.
      if (pulls.size() > 1) CHECK(distance(b.force, pulls.front().force, bar_ringing()) < 0.05);
      // Under linear and GIMP shapes every particle of the band softens
      // alike: the cohesive crack's curve. Under B-splines those at the
      // tent's middle break first and its flanks last: the same energy in a
      // steeper drop and a longer tail.
      if (shape != ShapeKind::bspline) CHECK(distance(b.force, cohesive, bar_ringing()) < 0.05);
      // The peak: the weak band's strength, plus what the plate must add to
      // give the bar's far part its speed once the band softens (at most the
      // impedance rho c times the speed).
      CHECK(b.peak_force > weak * strength * height);
      CHECK(b.peak_force < (weak * strength + impedance * speed) * height);
    }
  }
}

TEST_CASE("the paper's local damage law dissipates less per crack area the finer the cells", "[mpm][fracture]") {
  std::printf("\nbar pulled apart, local law (eta = 5)\n%8s %22s\n", "cell [m]", "dissipated [J/m2]");
  std::vector<double> local;
  for (double h : {0.025, 0.0125, 0.00625, 0.003125}) {
    local.push_back(pull(h, ShapeKind::bspline, true).dissipated_per_area);
    std::printf("%8.4f %22.4f\n", h, local.back());
  }
  CHECK(local.front() / local.back() > 2);
}

namespace {

// A notched beam in three-point bending, coal with the crack band: span 0.4 m,
// depth 0.1 m, a notch 1.25 cm wide to half the depth, loaded at mid-span by a
// plate pressed down at a set speed, each support a plate held still. Grids of
// 2 and 4 cells across the notch, so that its edges and its middle lie on grid
// lines (with 3 the crack starts at one of the notch's corners, not above its
// middle, and its curve departs from the others'), and linear shape functions:
// the notch's faces share no node, and the crack band softens as the cohesive
// crack.
constexpr double depth = 0.1, span = 0.4, notch = 0.05, width = 0.0125;           // [m]
constexpr double notch_left = 18 * width, centre = notch_left + 0.5 * width;      // [m]
constexpr double overall = 2 * centre, press = 0.005;                              // [m], [m/s]
// To past the peak and half down its softening.
constexpr double deflection = 8e-5;  // [m]

struct Bend {
  std::vector<double> force;  // [N/m] at deflections deflection k / samples
  double dissipated = 0;      // by damage [J/m]
};

Bend bend(double h, bool local) {
  const Grid<2> gr = grid(overall, depth + 2 * width, h);
  Settings<2> s;
  s.shape = ShapeKind::linear;
  s.courant = 0.5;
  for (double x : {centre - 0.5 * span, centre + 0.5 * span})
    s.platens.push_back({Vec<2>(x - width, -1), Vec<2>(x + width, 1e-9), 1, 0, 0.0});
  s.platens.push_back({Vec<2>(centre - width, depth - 1e-9), Vec<2>(centre + width, depth + 1), 1, 0, -press});
  auto all = block(gr, {0, 0}, {overall, depth}, coal.density, 2);
  Particles<2> particles;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Vec<2> x = all.x[i];
    if (std::abs(x.x() - centre) < 0.5 * width && x.y() < notch) continue;
    // Moving as the elastic beam would under the plate: a smaller wave at the start.
    const double from_support = std::min(x.x() - (centre - 0.5 * span), centre + 0.5 * span - x.x());
    const double shape = (3 * span * span * from_support - 4 * std::pow(from_support, 3)) / std::pow(span, 3);
    particles.add(x, Vec<2>(0, -press * shape), all.mass[i], all.volume[i], all.half_width[i], Mat<2>::Zero(), 0, 0);
  }
  std::vector<std::unique_ptr<Material<2>>> materials;
  // Strong in shear and compression, so that nothing breaks under the plates.
  DamageParameters d{10e6, 0.5, strength, 0.3, 5.0, std::nullopt};
  if (!local) {
    d.fracture_energy = fracture_energy;
    d.band_width = crack_cells(s.shape) * h;
  }
  materials.push_back(std::make_unique<ElasticDamage<2>>("coal", coal, d));
  Solver<2> solver(gr, std::move(materials), std::move(particles), s);
  Curve curve(deflection);
  while (-solver.platen_displacement()[2] < deflection) {
    solver.step(solver.stable_time_step());
    curve.add(-solver.platen_displacement()[2], -solver.platen_force()[2]);
  }
  return {std::move(curve.force), solver.energies().damage};
}

}  // namespace

TEST_CASE("crack band: a notched beam's peak load and softening converge as the grid is refined",
          "[mpm][fracture]") {
  // The beam's fundamental bending period, 2 pi / ((pi / S)^2 sqrt(E I / rho A)),
  // in samples of the plate's travel: the curves' ringing is averaged over it.
  const double period = 2 * 3.14159265358979 / (std::pow(3.14159265358979 / span, 2) *
                                                std::sqrt(coal.youngs_modulus * depth * depth / 12 / coal.density));
  const int half = static_cast<int>(0.5 * period * press / (deflection / samples));
  std::printf("\nnotched beam, three-point bending, G_f = %.2f J/m2\n%12s %8s %12s %24s %16s\n", fracture_energy,
              "law", "cell [m]", "peak [N/m]", "dissipated / (G_f lig.)", "from finest");
  std::vector<double> apart;
  for (bool local : {false, true}) {
    std::vector<Bend> runs;
    std::vector<double> peaks;
    for (double h : {width / 4, width / 2}) {
      const Bend& b = runs.emplace_back(bend(h, local));
      double peak = 0;
      for (int k = half; k < samples - half; ++k) peak = std::max(peak, running_mean(b.force, k, half));
      peaks.push_back(peak);
      std::printf("%12s %8.5f %12.1f %24.4f %16.4f\n", local ? "local" : "crack band", h, peak,
                  b.dissipated / (fracture_energy * (depth - notch)), distance(b.force, runs.front().force, half));
    }
    apart.push_back(distance(runs[1].force, runs[0].force, half));
    if (local) continue;
    for (const Bend& b : runs) {
      // The beam cracked within the deflection: its load fell well below its
      // peak, and the crack took at least half of G_f over the ligament.
      CHECK(running_mean(b.force, samples - 1 - half, half) < 0.8 * peaks.front());
      CHECK(b.dissipated > 0.5 * fracture_energy * (depth - notch));
    }
    // The crack band's peaks and curves agree within 3 % as the cells halve.
    CHECK(peaks[1] == Approx(peaks[0]).epsilon(0.03));
  }
  CHECK(apart[0] < 0.03);
  // The local law's curves part as the cells halve: its crack takes less
  // energy the narrower it is.
  CHECK(apart[1] > 3 * apart[0]);
}

namespace {

// Nonlocal damage in the bar: one material, a neck 1/8 of its height deep
// and 2.5 cm long at its middle (on the particle rows of every grid below) so
// that it breaks there, the damage-driving strain averaged over R = 2.5 cm
// with eta = 10 (its zone then takes more than the bar releases: no
// snap-back). Pulled until the bar carries about half its peak.
constexpr double radius = 0.025, neck_depth = 0.00625, neck_half = 0.0125, eta = 10;
constexpr double nonlocal_end = 4 * eta * strength / 6e9 * radius;  // [m] of plate travel

Pull pull_nonlocal(double h) {
  const auto all = block(grid(length + 3 * h, height, h), {0, 0}, {length, height}, coal.density, 2);
  Particles<2> particles;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Vec<2> x = all.x[i];
    if (std::abs(x.x() - 0.5 * length) < neck_half && x.y() > height - neck_depth) continue;
    particles.add(x, Vec<2>(speed * x.x() / length, 0), all.mass[i], all.volume[i], all.half_width[i], Mat<2>::Zero(),
                  0, 0);
  }
  DamageParameters d{1e6, 0.5, strength, 0.3, eta, std::nullopt};
  d.internal_length = radius;
  std::vector<std::unique_ptr<Material<2>>> materials;
  materials.push_back(std::make_unique<ElasticDamage<2>>("coal", coal, d));
  return pull_until(h, bar_settings(h, ShapeKind::linear), std::move(materials), std::move(particles), nonlocal_end,
                    height - neck_depth);
}

}  // namespace

TEST_CASE("nonlocal damage: a bar pulled apart dissipates the same energy, along the same curve, as the cells shrink "
          "at a fixed internal length", "[mpm][fracture][nonlocal]") {
  std::printf("\nbar pulled apart, nonlocal damage, R = %g m, eta = %g, linear shapes\n%8s %8s %20s %16s %16s %12s\n",
              radius, eta, "cell [m]", "R / h", "dissipated [J/m2]", "from finest", "curve from finest", "peak [kN/m]");
  std::vector<Pull> pulls;
  std::vector<double> apart;
  for (double h : {radius / 8, radius / 6, radius / 4, radius / 2}) {
    const Pull& b = pulls.emplace_back(pull_nonlocal(h));
    const double off = b.dissipated_per_area / pulls.front().dissipated_per_area - 1;
    apart.push_back(distance(b.force, pulls.front().force, bar_ringing(nonlocal_end)));
    std::printf("%8.5f %8.1f %20.4f %16.4f %16.4f %12.3f\n", h, radius / h, b.dissipated_per_area, off, apart.back(),
                b.peak_force / 1e3);
    // With R over at least four cells, the energy and the curve are the
    // finest run's within 3 %.
    if (radius / h >= 4) {
      CHECK(std::abs(off) < 0.03);
      CHECK(apart.back() < 0.03);
    }
    // The bar cracked: the load fell to below 70 % of its peak.
    CHECK(running_mean(b.force, samples - 1 - bar_ringing(nonlocal_end), bar_ringing(nonlocal_end)) < 0.7 * b.peak_force);
  }
  // The curves approach the finest one as the cells shrink.
  CHECK(apart[1] < apart[2]);
  CHECK(apart[2] < apart[3]);
}
