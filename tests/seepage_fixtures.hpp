#pragma once
// Small seepage problems built in code for the verification tests.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "seepage_fe/sampling.hpp"
#include "seepage_fe/solver.hpp"

namespace outburst::testing {

struct Problem {
  seepage::Mesh mesh;
  seepage::Model model;
};

// One region on a generated rectangle; `conditions` name left/right/bottom/top.
inline Problem rectangle_problem(seepage::Law law, Eigen::Vector2d size, std::array<int, 2> cells,
                                 seepage::Material material,
                                 std::vector<seepage::BoundaryCondition> conditions,
                                 std::array<double, 2> grading = {1.0, 1.0}) {
  seepage::StructuredMeshSpec spec;
  spec.size = size;
  spec.cells = cells;
  spec.grading = grading;
  spec.regions = {{"all", true, {}, {}}};
  seepage::Model model;
  model.law = law;
  model.materials = {material};
  model.boundary_conditions = std::move(conditions);
  return {seepage::make_structured_mesh(spec), model};
}

inline seepage::Solver rectangle_solver(seepage::Law law, Eigen::Vector2d size, std::array<int, 2> cells,
                                        seepage::Material material,
                                        std::vector<seepage::BoundaryCondition> conditions,
                                        seepage::Settings settings = {},
                                        std::array<double, 2> grading = {1.0, 1.0}) {
  auto p = rectangle_problem(law, size, cells, material, std::move(conditions), grading);
  return seepage::Solver(std::move(p.mesh), std::move(p.model), settings);
}

// One region on a generated box; `conditions` name left/right, bottom/top,
// back/front.
inline seepage::Solver3 box_solver(seepage::Law law, Eigen::Vector3d size, std::array<int, 3> cells,
                                   seepage::Material material, std::vector<seepage::BoundaryCondition> conditions,
                                   seepage::Settings settings = {},
                                   std::array<double, 3> grading = {1.0, 1.0, 1.0}) {
  seepage::BoxMeshSpec spec;
  spec.size = size;
  spec.cells = cells;
  spec.grading = grading;
  seepage::Model model;
  model.law = law;
  model.materials = {material};
  model.boundary_conditions = std::move(conditions);
  return seepage::Solver3(seepage::make_box_mesh(spec), model, settings);
}

inline seepage::BoundaryCondition fixed_pressure(const std::string& boundary, double p) {
  return {boundary, seepage::BoundaryCondition::Type::pressure, TimeFunction(p)};
}

// Advance to t_end in n equal steps.
inline void run_steps(seepage::Solver& solver, double t_end, int n) {
  const double dt = t_end / n;
  for (int i = 0; i < n; ++i) solver.advance(dt);
}

// Batches of 300 points scattered over the box lower..upper (a margin
// around the mesh) sampled over SIMD lanes, full batches and a short one,
// each with a hint that is its cell, none, a random cell or none the mesh
// has: every point gets what it gets alone, to the bit, hint included.
template <int Dim>
void check_batch_samples(const seepage::MeshOf<Dim>& mesh, const Eigen::Matrix<double, Dim, 1>& lower,
                         const Eigen::Matrix<double, Dim, 1>& upper) {
  using Sampler = seepage::SamplerOf<Dim>;
  using Point = typename Sampler::Point;
  const Sampler sampler(mesh);
  // A field with no special form: neither linear nor multilinear.
  Eigen::VectorXd u(static_cast<Eigen::Index>(mesh.num_nodes()));
  for (std::size_t k = 0; k < mesh.num_nodes(); ++k)
    u[static_cast<Eigen::Index>(k)] = std::sin(3 * mesh.nodes[k].x()) + mesh.nodes[k].y() * mesh.nodes[k].y();
  const int cells = static_cast<int>(mesh.num_cells()), points = 300;
  std::vector<double> x;
  std::vector<int> hints;
  std::uint32_t state = 12345;
  const auto uniform = [&state] {  // in [0, 1): a fixed sequence on every platform
    state = state * 1664525u + 1013904223u;
    return (state >> 8) * (1.0 / 16777216.0);
  };
  for (int k = 0; k < points; ++k) {
    Point point;
    for (int d = 0; d < Dim; ++d) {
      point[d] = lower[d] + (upper[d] - lower[d]) * uniform();
      x.push_back(point[d]);
    }
    switch (k % 4) {
      case 0: hints.push_back(sampler.cell_of(point)); break;
      case 1: hints.push_back(-1); break;
      case 2: hints.push_back(static_cast<int>(uniform() * cells)); break;
      default: hints.push_back(k % 8 == 3 ? cells + 5 : sampler.cell_of(point)); break;
    }
  }
  constexpr int lanes = Sampler::batch_lanes;
  int from_lanes = 0, outside = 0;
  typename Sampler::Batch batch;
  for (int start = 0; start < points; start += lanes) {
    const int count = std::min(lanes, points - start);
    std::vector<int> alone(hints.begin() + start, hints.begin() + start + count);
    sampler.sample(u, x.data() + Dim * start, count, hints.data() + start, batch);
    for (int k = 0; k < count; ++k) {
      const Point point = Eigen::Map<const Point>(x.data() + Dim * (start + k));
      const int given = alone[k];
      const auto expected = sampler.sample(u, point, &alone[k]);
      CHECK(hints[start + k] == alone[k]);
      REQUIRE((batch.found[k] != 0) == expected.has_value());
      if (!expected) {
        ++outside;
        continue;
      }
      from_lanes += given == alone[k];
      CHECK(batch.value[k] == expected->value);
      for (int d = 0; d < Dim; ++d) CHECK(batch.gradient[d][k] == expected->gradient[d]);
    }
  }
  CHECK(from_lanes > 50);
  CHECK(outside > 10);
}

}  // namespace outburst::testing
