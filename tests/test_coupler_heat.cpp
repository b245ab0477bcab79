// The coupler on the textbook partitioned problem (preCICE's heat tutorial):
// Dirichlet-Neumann coupling of the heat equation across a cut, with a
// solution both halves represent exactly.
#include <catch2/catch.hpp>

#include <cstdio>

#include "heat_participants.hpp"

using namespace outburst;
using namespace outburst::coupling;
using namespace outburst::testing;

namespace {

struct HeatRun {
  double mean_iterations, error;
  bool all_converged;
};

HeatRun run_heat(const char* kind, double relaxation) {
  const double dt = 0.1;
  HeatHalf left(HeatHalf::Side::dirichlet, 10, dt), right(HeatHalf::Side::neumann, 10, dt);
  SchemeSettings s;
  s.kind = SchemeSettings::Kind::implicit;
  s.to_second = {"heat_flux"};
  s.to_first = {{"temperature", 1e-10, 0}};
  s.acceleration.kind = kind;
  s.acceleration.relaxation = relaxation;
  s.max_iterations = 100;
  Coupling c(left, right, s);
  int iterations = 0;
  bool all = true;
  for (int w = 0; w < 10; ++w) {
    const auto& r = c.advance(dt);
    iterations += r.iterations;
    all = all && r.converged;
  }
  return {iterations / 10.0, std::max(left.max_error(), right.max_error()), all};
}

}  // namespace

TEST_CASE("partitioned heat: every acceleration matches the exact solution, in no more iterations than preCICE",
          "[coupler][heat]") {
  struct Row {
    const char* name;
    const char* kind;
    double relaxation, precice_iterations;
  };
  const Row rows[] = {{"constant 0.5", "constant", 0.5, 28.5},
                      {"Aitken", "aitken", 0.5, 16},
                      {"IQN-ILS", "iqn_ils", 0.1, 5}};
  std::printf("\npartitioned heat, 10 windows of 0.1, relative tolerance 1e-10\n%-14s %12s %10s %12s\n",
              "acceleration", "iterations", "preCICE", "max error");
  for (const auto& row : rows) {
    const HeatRun r = run_heat(row.kind, row.relaxation);
    std::printf("%-14s %12.1f %10.1f %12.2e\n", row.name, r.mean_iterations, row.precice_iterations, r.error);
    CHECK(r.all_converged);
    CHECK(r.error < 1e-8);
    CHECK(r.mean_iterations <= row.precice_iterations);
  }
}
