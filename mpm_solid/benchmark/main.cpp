// mpm-benchmark: particle-steps per second of the explicit step, for elastic,
// Drucker-Prager and elastic-damage material, linear and B-spline shapes, 1 and
// 2 threads, and the memory per particle (its own, and the grid's share).
//
// Problem: a square elastic (or plastic) block with 4 particles per cell
// released under gravity onto a fixed floor, so that every step does real
// work (moving particles, changing stresses).
// Usage: mpm-benchmark [particles ...] [--csv FILE] [--shape S ...] [--material M ...] [--threads T ...]
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "common/host.hpp"
#include "mpm_solid/materials/drucker_prager.hpp"
#include "mpm_solid/materials/elastic.hpp"
#include "mpm_solid/materials/elastic_damage.hpp"
#include "mpm_solid/materials/elastic_point.hpp"
#include "mpm_solid/scene_reader.hpp"
#include "mpm_solid/solver.hpp"

using namespace outburst;
using namespace outburst::mpm;

namespace {

// elastic_point: the elastic law written per material point
// (mpm_solid/materials/elastic_point.hpp), whose row against elastic's is
// what the per-point adapter costs.
enum class Model { elastic, elastic_point, drucker_prager, elastic_damage };
const char* model_name(Model m) {
  switch (m) {
    case Model::elastic: return "elastic";
    case Model::elastic_point: return "elastic_point";
    case Model::drucker_prager: return "drucker_prager";
    case Model::elastic_damage: return "elastic_damage";
  }
  return "";
}
const char* shape_name(ShapeKind s) {
  return s == ShapeKind::linear ? "linear" : s == ShapeKind::gimp ? "gimp" : "bspline";
}

struct Measured {
  double particle_steps_per_second;
  SolverMemory memory;
  long particles;
};

// A block of `particles` (n x n per cell, n^Dim particles a cell) dropped on
// a fixed floor between roller walls.
template <int Dim>
Measured measure(long particles, ShapeKind shape, Model model, int threads) {
  omp_set_num_threads(threads);
  const int per_cell = 2;
  const double per_side = std::pow(static_cast<double>(particles), 1.0 / Dim);
  const int side = static_cast<int>(std::lround(per_side / per_cell));
  const double h = 1.0;
  Grid<Dim> g;
  g.h = h;
  g.lower = Vec<Dim>::Zero();
  Vec<Dim> lo = Vec<Dim>::Zero(), hi;
  for (int d = 0; d < Dim; ++d) {
    // Twice the block's width across, room above it.
    g.cells[d] = d == 1 ? side + 4 : side * 2;
    lo[d] = d == 1 ? 0.0 : side / 2.0;
    hi[d] = d == 1 ? side : side * 1.5;
    g.upper[d] = g.cells[d] * h;
  }
  std::vector<Vec<Dim>> points;
  fill_cells<Dim>(g, per_cell, lo, hi, [](const Vec<Dim>&) { return true; }, points);
  Particles<Dim> p;
  const double spacing = h / per_cell, volume = Dim == 2 ? spacing * spacing : spacing * spacing * spacing;
  for (const auto& x : points)
    p.add(x, Vec<Dim>::Zero(), 1600 * volume, volume, 0.5 / per_cell, Mat<Dim>::Zero(), 0, 0);
  const Elasticity e{1600, 6e7, 0.3};
  std::vector<std::unique_ptr<Material<Dim>>> materials;
  switch (model) {
    case Model::elastic: materials.push_back(std::make_unique<LinearElastic<Dim>>("coal", e)); break;
    case Model::elastic_point: materials.push_back(elastic_point<Dim>("coal", e)); break;
    case Model::drucker_prager:
      materials.push_back(
          std::make_unique<DruckerPrager<Dim>>("coal", e, 1e4, 0.5, 0.0, DruckerPragerFit::Kind::outer));
      break;
    case Model::elastic_damage:
      // Weak enough that the block damages as it lands.
      materials.push_back(
          std::make_unique<ElasticDamage<Dim>>("coal", e, DamageParameters{2e4, 0.5, 2e3, 0.1, 5, std::nullopt}));
      break;
  }
  Settings<Dim> s;
  s.shape = shape;
  s.gravity[1] = -9.81;
  for (auto& w : s.walls) w = Wall{Wall::Type::roller};
  s.walls[2] = Wall{Wall::Type::fixed};
  s.walls[3] = Wall{};
  Solver<Dim> solver(g, std::move(materials), std::move(p), s);
  const double dt = solver.stable_time_step();
  const long n = static_cast<long>(solver.particles().size());
  const int warmup = 3;
  for (int i = 0; i < warmup; ++i) solver.step(dt);
  // Enough steps for about a second of work at 1e7 particle-steps/s.
  const int steps = static_cast<int>(std::max(5L, 10000000L / n));
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) solver.step(dt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {static_cast<double>(n) * steps / seconds, solver.memory(), n};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Particle-steps per second of the explicit MPM step (2D plane strain, 4 particles per cell; or 3D, "
               "8 per cell), and the memory per particle",
               "mpm-benchmark");
  std::vector<double> sizes{1e4, 1e5, 1e6};
  std::string csv_path;
  const int cores = omp_get_max_threads();
  std::vector<int> thread_counts{1, std::min(2, cores)};
  int dimension = 2;
  app.add_option("particles", sizes, "particles of each row's block (at least 100; 1e5 is read)")
      ->check(CLI::Range(100.0, 1e9))
      ->capture_default_str();
  app.add_option("--csv", csv_path, "also write the rows to this CSV file (docs/performance/mpm.md's table is written "
                                    "from mpm_solid/benchmark/mpm-benchmark.csv)");
  const std::map<std::string, ShapeKind> shape_words{
      {"linear", ShapeKind::linear}, {"gimp", ShapeKind::gimp}, {"bspline", ShapeKind::bspline}};
  const std::map<std::string, Model> model_words{
      {"elastic", Model::elastic},
      {"elastic_point", Model::elastic_point},
      {"drucker_prager", Model::drucker_prager},
      {"elastic_damage", Model::elastic_damage}};
  std::vector<std::string> shape_names{"linear", "bspline"}, model_names{"elastic", "drucker_prager", "elastic_damage"};
  app.add_option("--shape", shape_names, "the shape functions measured")
      ->check(CLI::IsMember(shape_words))
      ->capture_default_str();
  app.add_option("--material", model_names, "the materials measured")
      ->check(CLI::IsMember(model_words))
      ->capture_default_str();
  app.add_option("--threads", thread_counts,
                 "thread counts measured (default 1 and 2, at most the cores); the speed-up column is the last "
                 "over the first")
      ->check(CLI::Range(1, 256));
  app.add_option("--dimension", dimension,
                 "2: plane strain (2 x 2 particles per cell); 3: 3D (2 x 2 x 2 per cell, a cube of them)")
      ->check(CLI::IsMember({2, 3}))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a success; anything else is a bad command line (exit code 2, as every program here).
    return app.exit(e) == 0 ? 0 : 2;
  }
  std::vector<ShapeKind> shapes;
  std::vector<Model> models;
  for (const auto& name : shape_names) shapes.push_back(shape_words.at(name));
  for (const auto& name : model_names) models.push_back(model_words.at(name));
  std::FILE* csv = nullptr;
  if (!csv_path.empty()) {
    // The CSV's columns are one and two threads (docs/performance/mpm.md#throughput).
    if (thread_counts != std::vector<int>{1, std::min(2, cores)}) {
      std::fprintf(stderr, "mpm-benchmark: --csv writes the columns of 1 and 2 threads; leave --threads out\n");
      return 2;
    }
    csv = std::fopen(csv_path.c_str(), "w");
    if (!csv) {
      std::fprintf(stderr, "mpm-benchmark: cannot write %s\n", csv_path.c_str());
      return 2;
    }
    std::fprintf(csv, "particles,shape,material,one_thread,two_threads,speed_up,bytes_per_particle,"
                      "grid_bytes_per_particle,host\n");
  }
  const std::string host = host_description();
  std::printf("particle-steps per second (%s), %d cores, on %s\n\n",
              dimension == 2 ? "2D plane strain, 4 particles per cell" : "3D, 8 particles per cell", cores,
              host.c_str());
  // Memory per particle: the particles' own fields and per-step arrays, and
  // the grid's nodal arrays (with the last thread count's buffers) shared out over them.
  std::printf("%9s %-9s %-15s", "particles", "shape", "material");
  for (int t : thread_counts) std::printf(" %12s", fmt::format("{} thread{}", t, t == 1 ? "" : "s").c_str());
  std::printf(" %9s %14s %14s\n", "speed-up", "B/particle", "grid B/part.");
  for (double size : sizes)
    for (ShapeKind shape : shapes)
      for (Model model : models) {
        const long n = std::lround(size);
        std::vector<Measured> rows;
        for (int t : thread_counts)
          rows.push_back(dimension == 2 ? measure<2>(n, shape, model, t) : measure<3>(n, shape, model, t));
        const Measured& last = rows.back();
        const double count = static_cast<double>(last.particles);
        const double speed_up = last.particle_steps_per_second / rows.front().particle_steps_per_second;
        std::printf("%9ld %-9s %-15s", n, shape_name(shape), model_name(model));
        for (const auto& r : rows) std::printf(" %12.3e", r.particle_steps_per_second);
        std::printf(" %9.2f %14.0f %14.0f\n", speed_up, static_cast<double>(last.memory.particles) / count,
                    static_cast<double>(last.memory.grid) / count);
        std::fflush(stdout);
        // The CSV keeps its two columns (one and two threads) for the manual's table.
        if (csv)
          std::fprintf(csv, "%ld,%s,%s,%.4e,%.4e,%.3f,%.0f,%.0f,%s\n", n, shape_name(shape), model_name(model),
                       rows.front().particle_steps_per_second, last.particle_steps_per_second, speed_up,
                       static_cast<double>(last.memory.particles) / count,
                       static_cast<double>(last.memory.grid) / count, host_csv_field().c_str());
      }
  if (csv && std::fclose(csv) != 0) {
    std::fprintf(stderr, "mpm-benchmark: the CSV could not be written in full\n");
    return 1;
  }
  return 0;
}
