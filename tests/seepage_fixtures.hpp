#pragma once
// Small seepage problems built in code for the verification tests.

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

}  // namespace outburst::testing
