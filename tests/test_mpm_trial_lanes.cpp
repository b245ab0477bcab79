// The step's kinematics and elastic trial over a chunk of particles
// (deform_and_trial, a particle per SIMD lane, what every material's update
// runs) against the same step written with Eigen one particle at a time:
// F <- (I + dt L) F, V = V0 det F and the Jaumann-rate trial stress, in the
// plane and in 3D, with and without a particle's stiffness draw; and the
// members taken as a block or through their indices, and their velocity
// gradients read from the particles or from a chunk's lanes, alike, to the
// bit.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <span>
#include <vector>

#include "mpm_solid/material.hpp"

using namespace outburst::mpm;

namespace {

template <int Dim>
Particles<Dim> random_particles(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Particles<Dim> p;
  for (int i = 0; i < n; ++i) {
    Mat<Dim> stress;
    for (int e = 0; e < Dim * Dim; ++e) stress.data()[e] = 1e6 * u(rng);
    stress = (0.5 * (stress + stress.transpose())).eval();
    p.add(Vec<Dim>::Zero(), Vec<Dim>::Zero(), 1, 1 + 0.1 * u(rng), 0.25, stress, 1e6 * u(rng), 0);
    p.need_velocity_gradients();
    for (int e = 0; e < Dim * Dim; ++e) {
      // Strain rates over six decades, and deformation near the identity.
      p.velocity_gradient[i].data()[e] = u(rng) * std::pow(10.0, 3 * u(rng));
      p.deformation[i].data()[e] = (e % (Dim + 1) == 0 ? 1.0 : 0.0) + 0.1 * u(rng);
    }
  }
  return p;
}

// Relative difference, against the larger of the two and `floor`.
double relative(double a, double b, double floor) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), floor}); }

template <int Dim>
void lanes_match_one_particle_at_a_time(bool draws) {
  std::mt19937 rng(Dim + 10 * draws);
  const int n = 203;  // more than a chunk, and not a multiple of the SIMD width
  const double dt = 1e-4, lambda = 3.3e9, shear = 2.1e9;
  const Particles<Dim> start = random_particles<Dim>(n, rng);
  std::vector<double> stiffness(n);
  for (double& s : stiffness) s = std::uniform_real_distribution<double>(0.3, 3)(rng);
  const std::vector<double>* scale = draws ? &stiffness : nullptr;

  std::vector<int> block(n);
  std::iota(block.begin(), block.end(), 0);
  Particles<Dim> lanes = start;
  deform_and_trial(lanes, std::span<const int>(block), dt, lambda, shear, scale, lanes.stress, lanes.stress_zz);

  // The Jaumann-rate step as Eigen's expressions write it.
  double worst = 0;
  for (int i = 0; i < n; ++i) {
    const double s = draws ? stiffness[i] : 1.0, lam = s * lambda, g = s * shear;
    const Mat<Dim>& l = start.velocity_gradient[i];
    const Mat<Dim> f = (Mat<Dim>::Identity() + dt * l) * start.deformation[i];
    const Mat<Dim> d = 0.5 * (l + l.transpose()), w = 0.5 * (l - l.transpose());
    const Mat<Dim>& s0 = start.stress[i];
    const Mat<Dim> stress = s0 + dt * (lam * d.trace() * Mat<Dim>::Identity() + 2 * g * d + (w * s0 - s0 * w));
    for (int e = 0; e < Dim * Dim; ++e) {
      worst = std::max(worst, relative(lanes.deformation[i].data()[e], f.data()[e], 1.0));
      worst = std::max(worst, relative(lanes.stress[i].data()[e], stress.data()[e], s0.norm()));
    }
    worst = std::max(worst, relative(lanes.volume[i], start.volume0[i] * f.determinant(), 1.0));
    if constexpr (Dim == 2)
      worst = std::max(worst, relative(lanes.stress_zz[i], start.stress_zz[i] + dt * lam * d.trace(), s0.norm()));
  }
  // Round-off apart: the compiler may fuse different products in the two,
  // and in 3D Eigen fuses the rotation's products in some contexts only.
  CHECK(worst < 1e-13);

  // Members through their indices (a material's particles interleaved with
  // another's): every third particle left out. The members' step is the
  // block's to the bit, and the others are left as they were.
  std::vector<int> scattered;
  for (int i = 0; i < n; ++i)
    if (i % 3 != 1) scattered.push_back(i);
  Particles<Dim> indexed = start;
  deform_and_trial(indexed, std::span<const int>(scattered), dt, lambda, shear, scale, indexed.stress,
                   indexed.stress_zz);
  int differ = 0;
  for (int i = 0; i < n; ++i) {
    const Particles<Dim>& expected = i % 3 != 1 ? lanes : start;
    differ += expected.deformation[i] != indexed.deformation[i] || expected.stress[i] != indexed.stress[i] ||
              expected.volume[i] != indexed.volume[i];
    if constexpr (Dim == 2) differ += expected.stress_zz[i] != indexed.stress_zz[i];
  }
  CHECK(differ == 0);

  // The gradients handed over in each chunk's lanes, as the solver's fused
  // pass keeps them, the particles' own field cleared: the block's step to
  // the bit.
  Particles<Dim> handed = start;
  for (auto& l : handed.velocity_gradient) l.setZero();
  for (int first = 0; first < n; first += chunk_size) {
    const int count = std::min(chunk_size, n - first);
    std::vector<double> gradients(Dim * Dim * chunk_size, std::nan(""));
    for (int k = 0; k < count; ++k)
      for (int e = 0; e < Dim * Dim; ++e) gradients[e * chunk_size + k] = start.velocity_gradient[first + k].data()[e];
    deform_and_trial(handed, std::span<const int>(block).subspan(first, count), dt, lambda, shear, scale,
                     handed.stress, handed.stress_zz, gradients.data());
  }
  differ = 0;
  for (int i = 0; i < n; ++i) {
    differ += lanes.deformation[i] != handed.deformation[i] || lanes.stress[i] != handed.stress[i] ||
              lanes.volume[i] != handed.volume[i];
    if constexpr (Dim == 2) differ += lanes.stress_zz[i] != handed.stress_zz[i];
  }
  CHECK(differ == 0);
}

}  // namespace

TEST_CASE("the chunked kinematics and elastic trial give each particle its own step, to round-off, in the plane "
          "and in 3D, and members in a block or scattered the same bits",
          "[mpm][material]") {
  for (const bool draws : {false, true}) {
    INFO("a stiffness draw per particle: " << draws);
    lanes_match_one_particle_at_a_time<2>(draws);
    lanes_match_one_particle_at_a_time<3>(draws);
  }
}
