// mpm-benchmark: particle-steps per second of the explicit step, for elastic
// and Drucker-Prager material, linear and B-spline shapes, 1 and 2 threads.
//
// Problem: a square elastic (or plastic) block with 4 particles per cell
// released under gravity onto a fixed floor, so that every step does real
// work (moving particles, changing stresses).
// Usage: mpm-benchmark [particles ...]   (default 1e4 1e5 1e6)
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "mpm_solid/scene_reader.hpp"
#include "mpm_solid/solver.hpp"

using namespace outburst;
using namespace outburst::mpm;

namespace {

double particle_steps_per_second(long particles, ShapeKind shape, bool plastic, int threads) {
  omp_set_num_threads(threads);
  const int per_cell = 2;
  const int side = static_cast<int>(std::lround(std::sqrt(static_cast<double>(particles)) / per_cell));
  const double h = 1.0;
  Grid<2> g;
  g.h = h;
  g.lower = {0, 0};
  g.cells = {side * 2, side + 4};
  g.upper = {g.cells[0] * h, g.cells[1] * h};
  std::vector<Vec<2>> points;
  fill_cells(g, per_cell, Vec<2>(side / 2.0, 0), Vec<2>(side * 1.5, side), [](const Vec<2>&) { return true; }, points);
  Particles<2> p;
  const double volume = (h / per_cell) * (h / per_cell);
  for (const auto& x : points) p.add(x, Vec<2>::Zero(), 1600 * volume, volume, 0.5 / per_cell, Mat<2>::Zero(), 0, 0);
  const Elasticity e{1600, 6e7, 0.3};
  std::vector<std::unique_ptr<Material>> materials;
  if (plastic)
    materials.push_back(std::make_unique<DruckerPrager>("coal", e, 1e4, 0.5, 0.0, DruckerPragerFit::Kind::outer));
  else
    materials.push_back(std::make_unique<LinearElastic>("coal", e));
  Settings s;
  s.shape = shape;
  s.gravity = {0, -9.81};
  s.walls = {Wall{Wall::Type::roller}, Wall{Wall::Type::roller}, Wall{Wall::Type::fixed}, Wall{}};
  Solver solver(g, std::move(materials), std::move(p), s);
  const double dt = solver.stable_time_step();
  const long n = static_cast<long>(solver.particles().size());
  const int warmup = 3;
  for (int i = 0; i < warmup; ++i) solver.step(dt);
  // Enough steps for about a second of work at 1e7 particle-steps/s.
  const int steps = static_cast<int>(std::max(5L, 10000000L / n));
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) solver.step(dt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return static_cast<double>(n) * steps / seconds;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<long> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::atol(argv[i]));
  if (sizes.empty()) sizes = {10000, 100000, 1000000};
  const int cores = omp_get_max_threads();
  std::printf("particle-steps per second (2D plane strain, 4 particles per cell), %d cores\n\n", cores);
  std::printf("%9s %-9s %-15s %12s %12s %9s\n", "particles", "shape", "material", "1 thread", "2 threads", "speed-up");
  for (long n : sizes)
    for (ShapeKind shape : {ShapeKind::linear, ShapeKind::bspline})
      for (bool plastic : {false, true}) {
        const double one = particle_steps_per_second(n, shape, plastic, 1);
        const double two = particle_steps_per_second(n, shape, plastic, std::min(2, cores));
        std::printf("%9ld %-9s %-15s %12.3e %12.3e %9.2f\n", n, shape == ShapeKind::linear ? "linear" : "bspline",
                    plastic ? "drucker_prager" : "elastic", one, two, two / one);
        std::fflush(stdout);
      }
  return 0;
}
