#pragma once
// Small seepage problems built in code for the verification tests.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "seepage_fe/cell_locator.hpp"
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
// around the mesh), a few of them not a number, sampled over SIMD lanes, full
// batches and a short one, each with a hint that is its cell, none, a random
// cell or none the mesh has: every point gets what it gets alone, to the bit,
// hint included. A mesh with parallelograms (parallelepipeds) must have had
// some points taken by the lanes.
template <int Dim>
void check_batch_samples(const seepage::MeshOf<Dim>& mesh, const Eigen::Matrix<double, Dim, 1>& lower,
                         const Eigen::Matrix<double, Dim, 1>& upper, bool parallelograms) {
  using Sampler = seepage::SamplerOf<Dim>;
  using Point = typename Sampler::Point;
  const Sampler sampler(mesh);
  const seepage::CellLocatorOf<Dim> locator(mesh);
  // A field with no special form, with a term in every coordinate and a mixed
  // one, so that every entry of an inverse Jacobian counts.
  Eigen::VectorXd u(static_cast<Eigen::Index>(mesh.num_nodes()));
  for (std::size_t k = 0; k < mesh.num_nodes(); ++k) {
    const Point& x = mesh.nodes[k];
    u[static_cast<Eigen::Index>(k)] = std::sin(3 * x.x()) + x.y() * x.y() + 0.5 * x.x() * x[Dim - 1];
  }
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
    for (int d = 0; d < Dim; ++d) point[d] = lower[d] + (upper[d] - lower[d]) * uniform();
    if (k % 37 == 5) point[k % Dim] = std::numeric_limits<double>::quiet_NaN();
    x.insert(x.end(), point.data(), point.data() + Dim);
    switch (k % 4) {
      case 0: hints.push_back(point.allFinite() ? sampler.cell_of(point) : k % cells); break;
      case 1: hints.push_back(-1); break;
      case 2: hints.push_back(static_cast<int>(uniform() * cells)); break;
      default: hints.push_back(k % 8 == 3 ? cells + 5 : sampler.cell_of(point)); break;
    }
  }
  constexpr int lanes = Sampler::batch_lanes;
  int by_lanes = 0, outside = 0, batches_by_lanes = 0;
  typename Sampler::Batch batch;
  for (int start = 0; start < points; start += lanes) {
    const int count = std::min(lanes, points - start);
    std::vector<int> alone(hints.begin() + start, hints.begin() + start + count);
    sampler.sample(u, x.data() + Dim * start, count, hints.data() + start, batch);
    batches_by_lanes += batch.by_lanes;
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
      // Found in the parallelogram its hint named: the lanes' case.
      by_lanes += given == alone[k] && std::isfinite(locator.affine_maps()[static_cast<std::size_t>(given)].centre[0]);
      CHECK(batch.value[k] == expected->value);
      for (int d = 0; d < Dim; ++d) CHECK(batch.gradient[d][k] == expected->gradient[d]);
    }
  }
  CHECK(outside > 10);
  CHECK(batches_by_lanes == by_lanes);
  if (parallelograms)
    CHECK(by_lanes > 50);
  else
    CHECK(by_lanes == 0);
}

}  // namespace outburst::testing
