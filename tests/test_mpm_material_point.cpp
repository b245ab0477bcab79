// A constitutive law written for one material point (mpm_solid/material_point.hpp)
// against the same law written over SIMD lanes: the elastic law both ways.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mpm_fixtures.hpp"
#include "mpm_solid/materials/elastic.hpp"
#include "mpm_solid/materials/elastic_point.hpp"

using namespace outburst;
using namespace outburst::mpm;

namespace {

const Elasticity coal{1600, 6e9, 0.3};

// The largest entry of a - b over the largest of a, over every particle's
// stress (and plane strain's out-of-plane one).
template <int Dim>
double stress_difference(const Particles<Dim>& a, const Particles<Dim>& b) {
  double largest = 0, difference = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    largest = std::max(largest, a.stress[i].cwiseAbs().maxCoeff());
    difference = std::max(difference, (a.stress[i] - b.stress[i]).cwiseAbs().maxCoeff());
    if constexpr (Dim == 2) difference = std::max(difference, std::abs(a.stress_zz[i] - b.stress_zz[i]));
  }
  return difference / largest;
}

// One particle driven by a velocity gradient with stretch and spin, each
// form on its own copy: the stresses, F and volumes after `steps`.
template <int Dim>
void drive_both(const Mat<Dim>& l, int steps, double dt, double& stress_error, double& volume_error) {
  const LinearElastic<Dim> lanes("coal", coal);
  const auto point = elastic_point<Dim>("coal", coal);
  Particles<Dim> a, b;
  for (auto* p : {&a, &b}) {
    p->add(Vec<Dim>::Zero(), Vec<Dim>::Zero(), 1, 1, 0.25, Mat<Dim>::Zero(), 0, 0);
    p->need_velocity_gradients();
    p->velocity_gradient[0] = l;
  }
  for (int s = 0; s < steps; ++s) {
    lanes.update_stress(a, {0}, dt);
    point->update_stress(b, {0}, dt);
  }
  stress_error = stress_difference(a, b);
  volume_error = std::abs(a.volume[0] - b.volume[0]) / a.volume[0] +
                 (a.deformation[0] - b.deformation[0]).cwiseAbs().maxCoeff();
}

// A block dropped on a fixed floor, run by a solver with each form of the law.
template <int Dim>
Particles<Dim> dropped_block(bool per_point, int steps) {
  Grid<Dim> g;
  Vec<Dim> lo, hi;
  if constexpr (Dim == 2) {
    g = testing::grid(4, 4, 0.25);
    lo = {1, 0.5};
    hi = {3, 2};
  } else {
    g = testing::grid(Vec<3>(2, 2, 2), 0.25);
    lo = {0.5, 0.5, 0.25};
    hi = {1.5, 1.5, 1};
  }
  std::vector<std::unique_ptr<Material<Dim>>> materials;
  if (per_point)
    materials.push_back(elastic_point<Dim>("coal", coal));
  else
    materials.push_back(std::make_unique<LinearElastic<Dim>>("coal", coal));
  Settings<Dim> settings;
  settings.gravity[Dim - 1] = -9.81;
  settings.walls[2 * (Dim - 1)] = {Wall::Type::fixed, 0};
  Solver<Dim> solver(g, std::move(materials), testing::block<Dim>(g, lo, hi, coal.density, 2), settings);
  const double dt = solver.stable_time_step();
  for (int s = 0; s < steps; ++s) solver.step(dt);
  return solver.particles();
}

}  // namespace

TEST_CASE("a law written per material point gives the lane-wise law's stresses to round-off", "[mpm][material]") {
  double stress_error = 1, volume_error = 1;
  Mat<2> l2;
  l2 << 0.3, 1.1, -0.7, -0.2;  // stretch, shear and spin
  drive_both<2>(l2, 200, 1e-3, stress_error, volume_error);
  std::printf("per point against lanes, one particle, 200 steps: plane strain %.2e (stress) %.2e (F, V)\n",
              stress_error, volume_error);
  CHECK(stress_error < 1e-13);
  CHECK(volume_error < 1e-13);
  Mat<3> l3;
  l3 << 0.3, 1.1, -0.4, -0.7, -0.2, 0.5, 0.6, -0.9, 0.1;
  drive_both<3>(l3, 200, 1e-3, stress_error, volume_error);
  std::printf("per point against lanes, one particle, 200 steps: 3D %.2e (stress) %.2e (F, V)\n", stress_error,
              volume_error);
  CHECK(stress_error < 1e-13);
  CHECK(volume_error < 1e-13);
}

TEST_CASE("a law written per material point runs a dropped block as the lane-wise law does", "[mpm][material]") {
  const auto plane_lanes = dropped_block<2>(false, 300), plane_point = dropped_block<2>(true, 300);
  const auto solid_lanes = dropped_block<3>(false, 100), solid_point = dropped_block<3>(true, 100);
  double moved = 0, moved_3d = 0;
  for (std::size_t i = 0; i < plane_lanes.size(); ++i)
    moved = std::max(moved, (plane_lanes.x[i] - plane_point.x[i]).norm());
  for (std::size_t i = 0; i < solid_lanes.size(); ++i)
    moved_3d = std::max(moved_3d, (solid_lanes.x[i] - solid_point.x[i]).norm());
  const double stresses = stress_difference(plane_lanes, plane_point),
               stresses_3d = stress_difference(solid_lanes, solid_point);
  std::printf("per point against lanes, dropped block: plane strain %.2e m, stress %.2e; 3D %.2e m, stress %.2e\n",
              moved, stresses, moved_3d, stresses_3d);
  CHECK(moved < 1e-12);
  CHECK(moved_3d < 1e-12);
  CHECK(stresses < 1e-9);
  CHECK(stresses_3d < 1e-9);
}
