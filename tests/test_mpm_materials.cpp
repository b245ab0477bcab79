// Single-point stress paths of the constitutive models against hand-computed
// answers: one particle driven by a prescribed velocity gradient.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include <Eigen/Eigenvalues>

#include "mpm_solid/materials/drucker_prager.hpp"
#include "mpm_solid/materials/elastic.hpp"
#include "mpm_solid/materials/elastic_damage.hpp"
#include "mpm_solid/solver.hpp"

using namespace outburst;
using namespace outburst::mpm;

namespace {

constexpr double deg = 3.14159265358979323846 / 180;
const Elasticity coal{1600, 6e9, 0.4};

Particles<2> one_particle() {
  Particles<2> p;
  p.add(Vec<2>::Zero(), Vec<2>::Zero(), 1, 1, 0.25, Mat<2>::Zero(), 0, 0);
  p.need_plastic_strain();  // what the damage and plasticity models keep
  p.need_damage();
  p.need_velocity_gradients();  // as a solver's split passes store them
  return p;
}

// Drive the particle with a constant velocity gradient for `steps` of dt.
void drive(const Material<2>& m, Particles<2>& p, const Mat<2>& l, int steps, double dt) {
  p.velocity_gradient[0] = l;
  for (int s = 0; s < steps; ++s) m.update_stress(p, {0}, dt);
}

}  // namespace

TEST_CASE("Drucker-Prager coefficients match the paper's outer-cone fit", "[mpm][material]") {
  const auto [alpha, k] = DruckerPragerFit::coefficients(DruckerPragerFit::Kind::outer, 1e6, 30 * deg);
  CHECK(alpha == Approx(0.6928).epsilon(1e-4));  // model-notes section 4
  CHECK(k == Approx(1.2e6).epsilon(1e-4));
  // The inner cone is inside the outer one; the plane-strain fit inside both.
  const auto inner = DruckerPragerFit::coefficients(DruckerPragerFit::Kind::inner, 1e6, 30 * deg);
  const auto plane = DruckerPragerFit::coefficients(DruckerPragerFit::Kind::plane_strain, 1e6, 30 * deg);
  CHECK(inner.second < k);
  CHECK(plane.second < inner.second);
}

TEST_CASE("elastic Jaumann rate: uniaxial strain and a rigid rotation", "[mpm][material]") {
  LinearElastic<2> m("coal", coal);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = -1e-3;  // compress along x at 1e-3 /s for 1 s
  drive(m, p, l, 100, 0.01);
  const double lambda = coal.lame_lambda(), g = coal.shear_modulus();
  CHECK(p.stress[0](0, 0) == Approx(-(lambda + 2 * g) * 1e-3).epsilon(1e-12));
  CHECK(p.stress[0](1, 1) == Approx(-lambda * 1e-3).epsilon(1e-12));
  CHECK(p.stress_zz[0] == Approx(-lambda * 1e-3).epsilon(1e-12));
  // A pure spin rotates the stress without changing its invariants.
  const Mat<2> before = p.stress[0];
  Mat<2> spin;
  spin << 0, -1, 1, 0;  // rotation at 1 rad/s
  drive(m, p, spin, 10000, 3.14159265358979 / 2 / 10000);  // a quarter turn in small steps
  CHECK(p.stress[0].trace() == Approx(before.trace()).epsilon(1e-9));
  CHECK(p.stress[0].determinant() == Approx(before.determinant()).epsilon(1e-3));
  CHECK(p.stress[0](0, 0) == Approx(before(1, 1)).epsilon(1e-3));  // axes swapped
}

TEST_CASE("Drucker-Prager compression with shear stays on the cone as computed by hand",
          "[mpm][material]") {
  // Compress along x, stretch along y a little less: volume shrinks slowly while
  // shear grows until the cone is reached. With no dilation, plastic flow keeps
  // the volume, so the mean stress is K times the total volumetric strain, and
  // on the cone sqrt(J2) = k - alpha * mean.
  DruckerPrager<2> m("coal", coal, 1e6, 30 * deg, 0.0, DruckerPragerFit::Kind::outer);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = -1.0;
  l(1, 1) = 0.9;
  const double strain = 2e-3;  // yield starts near 3.6e-4
  drive(m, p, l, 2000, strain / 2000);
  const double bulk = coal.lame_lambda() + 2.0 / 3.0 * coal.shear_modulus();
  const double mean = (p.stress[0].trace() + p.stress_zz[0]) / 3;
  CHECK(mean == Approx(-bulk * 0.1 * strain).epsilon(1e-9));
  CHECK(m.yield(p.stress[0], p.stress_zz[0]) == Approx(0).margin(1e-9 * m.k()));
  const Mat<2> dev = p.stress[0] - mean * Mat<2>::Identity();
  const double sqrt_j2 = std::sqrt(0.5 * (dev.squaredNorm() + std::pow(p.stress_zz[0] - mean, 2)));
  CHECK(sqrt_j2 == Approx(m.k() - m.alpha() * mean).epsilon(1e-9));
  CHECK(p.plastic_strain[0] > 0);
}

TEST_CASE("Drucker-Prager tension returns to the apex: hydrostatic k / alpha", "[mpm][material]") {
  DruckerPrager<2> m("coal", coal, 1e6, 30 * deg, 0.0, DruckerPragerFit::Kind::outer);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = 1.0;
  drive(m, p, l, 100, 1e-5);  // 1e-3 of extension, far past the apex
  const double apex = m.k() / m.alpha();  // mean stress at the apex, tension
  CHECK(p.stress[0](0, 0) == Approx(apex).epsilon(1e-12));
  CHECK(p.stress[0](1, 1) == Approx(apex).epsilon(1e-12));
  CHECK(p.stress_zz[0] == Approx(apex).epsilon(1e-12));
  CHECK(std::abs(p.stress[0](0, 1)) < 1e-9 * apex);
}

TEST_CASE("Drucker-Prager without friction or cohesion carries no shear: a fluid's mean stress alone",
          "[mpm][material]") {
  // alpha = k = 0: a cylinder of radius 0, whose return leaves sqrt(J2) at 0
  // give or take round-off. Before: a return that round-off took below 0 went
  // to the apex of a cone this has none of, k / alpha = 0 / 0, and the run
  // died at its second step with a non-finite stress.
  const Elasticity sand{1800, 10e6, 0.3};
  const double g = sand.shear_modulus(), bulk = sand.lame_lambda() + 2.0 / 3.0 * g;
  int returned = 0;
  for (const double shear : {1e3, 2e3, 12345.0, 1e5, 3e5, 7.7e6}) {
    for (const double mean : {-2e4, 0.0, 5e3}) {
      INFO("shear " << shear << " Pa, mean " << mean << " Pa");
      Mat<2> s;
      s << mean + 0.1 * shear, shear, shear, mean - 0.1 * shear;
      double s_zz = mean, work = -1;
      drucker_prager_return<2>(0.0, 0.0, 0.0, g, bulk, s, s_zz, &work);
      REQUIRE(s.allFinite());
      REQUIRE(std::isfinite(s_zz));
      CHECK(std::abs(s(0, 1)) <= 1e-12 * shear);
      CHECK(s(0, 0) == Approx(mean).margin(1e-12 * shear));
      CHECK(s(1, 1) == Approx(mean).margin(1e-12 * shear));
      CHECK(s_zz == Approx(mean).margin(1e-12 * shear));
      CHECK(work >= 0);
      ++returned;
    }
  }
  CHECK(returned == 18);
}

TEST_CASE("Drucker-Prager below the yield surface is elastic", "[mpm][material]") {
  DruckerPrager<2> plastic("coal", coal, 1e6, 30 * deg, 0.0, DruckerPragerFit::Kind::outer);
  LinearElastic<2> elastic("coal", coal);
  auto a = one_particle(), b = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = -1e-5;
  drive(plastic, a, l, 10, 1.0);
  drive(elastic, b, l, 10, 1.0);
  CHECK(plastic.yield(a.stress[0], a.stress_zz[0]) < 0);
  CHECK(a.stress[0] == b.stress[0]);
  CHECK(a.plastic_strain[0] == 0);
}

namespace {

// n velocity gradients [1/s], each particle's own: principal stretch rates of
// eight amplitudes (0.05 to 0.93 per second along each direction), turned
// by the particle's own angle, and a spin.
std::vector<Mat<2>> own_paths(int n) {
  std::vector<Mat<2>> l(n);
  for (int k = 0; k < n; ++k) {
    const double size = 0.05 + (k % 8) / 8.0, angle = 0.7 * k;
    const double a = size * std::sin(1.3 * k), b = size * std::cos(2.1 * k), spin = 0.2 * std::sin(0.5 * k);
    Mat<2> r;
    r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    l[k] = r * Vec<2>(a, b).asDiagonal() * r.transpose();
    l[k](0, 1) -= spin, l[k](1, 0) += spin;
  }
  return l;
}

}  // namespace

TEST_CASE("Drucker-Prager: a chunk screened over SIMD lanes ends as each particle's trial returned alone",
          "[mpm][material]") {
  // A chunk and a few more particles along their own strain paths: elastic,
  // onto the cone in compression, past the apex in tension, unloading, and
  // one held in hydrostatic tension beyond the apex (a zero multiplier that
  // still does plastic work). In the plane, lanes screen out a chunk's
  // particles that surely lie inside the cone and the public return takes
  // the rest; the reference is that return applied to every particle's
  // elastic trial, formed here in another translation unit (its fused
  // multiply-adds may sit elsewhere: an ulp, which a return's sum of a mean
  // and a deviator of nearly opposite size makes 1e-15 of the stress a few
  // times over). Members reached through a list (evens, then odds) end the
  // same.
  const double dilation = GENERATE(0.0, 10 * deg);
  INFO("dilation angle " << dilation / deg << " deg");
  const DruckerPrager<2> m("coal", coal, 0.3e6, 30 * deg, dilation, DruckerPragerFit::Kind::outer);
  const int n = chunk_size + 5;
  Particles<2> together;
  for (int k = 0; k < n; ++k) together.add({0.1 * k, 0}, {0, 0}, 1, 1, 0.25, Mat<2>::Zero(), 0, 0);
  std::vector<int> members(n), evens, odds;
  std::iota(members.begin(), members.end(), 0);
  for (int k = 0; k < n; ++k) (k % 2 ? odds : evens).push_back(k);
  m.create_fields(together, members);
  together.need_velocity_gradients();
  std::vector<Mat<2>> l = own_paths(n);
  l[0].setZero();               // never loaded
  l[1] = Mat<2>::Identity();    // spreading: past the apex
  l[2] = -Mat<2>::Identity();   // squeezed equally: no shear, elastic
  l[3].setZero();               // held in hydrostatic tension beyond the apex
  const double apex = m.k() / m.alpha(), bulk = m.lame_lambda() + 2.0 / 3.0 * m.shear_modulus();
  // A power of two past the apex: the mean of three is exact, the deviator zero.
  const double held = std::ldexp(1.0, std::ilogb(apex) + 1);
  together.stress[3] = held * Mat<2>::Identity();
  together.stress_zz[3] = held;
  const double per_multiplier = std::sqrt(2.0 / 3.0 * (0.5 + std::pow(
      DruckerPragerFit::coefficients(DruckerPragerFit::Kind::outer, 0, dilation).first, 2) / 3));
  int returned = 0, apexes = 0;
  bool held_work = false;
  bool first = true;
  for (const double sign : {1.0, 1.0, -0.5}) {
    for (int k = 0; k < n; ++k) together.velocity_gradient[k] = sign * l[k];
    for (int s = 0; s < 60; ++s, first = false) {
      Particles<2> trial = together;
      deform_and_trial(trial, std::span<const int>(members), 2e-6, m.lame_lambda(), m.shear_modulus(), nullptr,
                       trial.stress, trial.stress_zz);
      std::vector<double> multiplier(n);
      double work_sum = 0, scale_sum = 0;
      for (int k = 0; k < n; ++k) {
        double work = 0;
        multiplier[k] = m.return_map(trial.stress[k], trial.stress_zz[k], &work);
        work_sum += trial.volume[k] * work;
        scale_sum += trial.volume[k] * trial.stress[k].squaredNorm() / m.shear_modulus();
        if (k == 3 && first) {
          // The mean stress let go to the apex: work apex (held - apex) / K.
          CHECK(multiplier[k] == 0);
          CHECK(work == Approx(apex * (held - apex) / bulk).epsilon(1e-12));
          held_work = work > 0;
        }
      }
      const std::vector<double> strain_before = together.plastic_strain;
      Dissipation d;
      if (s % 2) {
        d = m.update_stress(together, members, 2e-6);
      } else {
        d += m.update_stress(together, evens, 2e-6);
        d += m.update_stress(together, odds, 2e-6);
      }
      CHECK(d.plastic == Approx(work_sum).margin(1e-12 * scale_sum));
      for (int k = 0; k < n; ++k) {
        CAPTURE(k, s, sign);
        const double size = trial.stress[k].norm() + std::abs(trial.stress_zz[k]);
        CHECK((together.stress[k] - trial.stress[k]).norm() <= 1e-13 * size);
        CHECK(std::abs(together.stress_zz[k] - trial.stress_zz[k]) <= 1e-13 * size);
        CHECK(together.plastic_strain[k] - strain_before[k] ==
              Approx(per_multiplier * multiplier[k]).margin(1e-13 * (size / m.shear_modulus())));
        returned += multiplier[k] > 0;
        apexes += multiplier[k] > 0 && together.stress[k](0, 1) == 0 && together.stress[k](0, 0) == apex;
      }
    }
  }
  CHECK(held_work);
  CHECK(returned > n);     // many particles on the cone, over many steps
  CHECK(apexes > 0);       // some of them at its apex
  CHECK(together.plastic_strain[0] == 0);
  CHECK(together.plastic_strain[2] == 0);
}

TEST_CASE("Drucker-Prager: the lanes' screen passes no stress the return would move, however near the cone",
          "[mpm][material]") {
  // Stresses on, just inside and just outside the cone (sqrt(J2) = (k -
  // alpha mean)(1 + e), e from -1e-9 to 1e-9 and 0), in tension and
  // compression, with a chunk's worth of deviator directions and an
  // out-of-plane part; for cohesionless sand also at magnitudes from 1e-300
  // to 1e150, and states whose squares or mean overflow. With no velocity
  // gradient the trial is the stress itself, so the update must leave
  // exactly the states the public return leaves, and move the others where
  // it moves them (to an ulp: the return's fused multiply-adds, inlined in
  // the update, may sit elsewhere than in the public return).
  const double cohesion = GENERATE(0.3e6, 0.0);
  INFO("cohesion " << cohesion << " Pa");
  const DruckerPrager<2> m("coal", coal, cohesion, 30 * deg, 10 * deg, DruckerPragerFit::Kind::outer);
  const double apex = m.k() / m.alpha();
  const std::vector<double> means = cohesion > 0 ? std::vector<double>{-50 * apex, -apex, 0.0, 0.5 * apex, 0.999 * apex}
                                                 : std::vector<double>{-1e-300, -1e-156, -1.0, -1e6, -1e150};
  Particles<2> p;
  std::vector<Mat<2>> expected;
  std::vector<double> expected_zz;
  std::vector<bool> moves;
  const auto add = [&](const Mat<2>& s, double s_zz) {
    p.add({0.1 * static_cast<double>(p.size()), 0}, {0, 0}, 1, 1, 0.25, s, s_zz, 0);
    Mat<2> r = s;
    double r_zz = s_zz;
    m.return_map(r, r_zz);
    // NaN != NaN: a return to NaN counts as a move.
    moves.push_back(!(r == s && r_zz == s_zz));
    expected.push_back(r);
    expected_zz.push_back(r_zz);
  };
  for (const double mean : means) {
    for (const double e : {-1e-9, -1e-12, -1e-15, -2e-16, 0.0, 2e-16, 1e-15, 1e-12, 1e-9}) {
      for (int d = 0; d < 8; ++d) {
        // A deviator (xx, yy, xy, zz summing to zero on the diagonal) of unit sqrt(J2).
        const double a = std::cos(0.9 * d), b = std::sin(0.9 * d), c = 0.3 * std::sin(2.3 * d);
        Mat<2> dev;
        dev << a, c, c, b;
        const double dev_zz = -(a + b);
        const double unit = std::sqrt(0.5 * (dev.squaredNorm() + dev_zz * dev_zz));
        const double size = (m.k() - m.alpha() * mean) * (1 + e) / unit;
        add(mean * Mat<2>::Identity() + size * dev, mean + size * dev_zz);
      }
    }
  }
  Mat<2> sheared;
  sheared << -1e160, 1e160, 1e160, -1e160;  // outside the cone; its J2 overflows
  add(sheared, -1e160);
  add(-1e308 * Mat<2>::Identity(), -1e308);  // its mean overflows
  std::vector<int> members(p.size());
  std::iota(members.begin(), members.end(), 0);
  m.create_fields(p, members);
  p.need_velocity_gradients();
  for (auto& l : p.velocity_gradient) l.setZero();
  m.update_stress(p, members, 1e-6);
  int moved = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    CAPTURE(k, expected[k], expected_zz[k], p.stress[k], p.stress_zz[k]);
    moved += moves[k];
    const double size = expected[k].cwiseAbs().maxCoeff() + std::abs(expected_zz[k]);
    const auto agrees = [&](double got, double want) {
      return std::isnan(want) ? std::isnan(got) : moves[k] ? std::abs(got - want) <= 1e-15 * size : got == want;
    };
    for (int e = 0; e < 4; ++e) CHECK(agrees(p.stress[k](e), expected[k](e)));
    CHECK(agrees(p.stress_zz[k], expected_zz[k]));
  }
  // Some of the states the return moves, some it leaves.
  CHECK(moved > 0);
  CHECK(moved < static_cast<int>(p.size()));
}

TEST_CASE("Drucker-Prager: a NaN stress in a chunk stays NaN and leaves its neighbours alone", "[mpm][material]") {
  // The screen sends a NaN trial to the return, as the per-particle path
  // did: all its stress becomes NaN, not only the entry that was, and the
  // solver's health check sees it.
  const DruckerPrager<2> m("coal", coal, 0.3e6, 30 * deg, 0.0, DruckerPragerFit::Kind::outer);
  Particles<2> p;
  for (int k = 0; k < 3; ++k) p.add({0.1 * k, 0}, {0, 0}, 1, 1, 0.25, Mat<2>::Zero(), 0, 0);
  const std::vector<int> members{0, 1, 2};
  m.create_fields(p, members);
  p.need_velocity_gradients();
  for (auto& l : p.velocity_gradient) l << -1e-3, 0, 0, 0;
  p.stress[1](0, 0) = std::nan("");
  m.update_stress(p, members, 1.0);
  CHECK(std::isnan(p.stress[1](1, 1)));
  CHECK(std::isnan(p.plastic_strain[1]));
  CHECK(p.stress[0] == p.stress[2]);
  CHECK(std::isfinite(p.stress[0].norm()));
}

namespace {

const DamageParameters coal_damage{1e6, 30 * deg, 0.2e6, 0.1, 5.0, std::nullopt};

}  // namespace

TEST_CASE("elastic-damage: uniaxial-strain tension follows D = 1 - f_tr / (E0 eps)", "[mpm][material][damage]") {
  ElasticDamage<2> m("coal", coal, coal_damage);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = 1.0;
  const double eps = 4e-5;  // past f_t (at 1.6e-5) and below eta f_t / E0 (1.7e-4)
  drive(m, p, l, 400, eps / 400);
  const double p_modulus = coal.lame_lambda() + 2 * coal.shear_modulus();
  // In uniaxial strain the largest principal strain is eps itself.
  const double expected = 1 - 0.1 * 0.2e6 / (6e9 * eps);
  CHECK(p.damage[0] == Approx(expected).epsilon(1e-9));
  CHECK(p.stress[0](0, 0) == Approx((1 - expected) * p_modulus * eps).epsilon(1e-9));
  CHECK(p.effective_stress[0](0, 0) == Approx(p_modulus * eps).epsilon(1e-9));
}

TEST_CASE("elastic-damage: broken coal carries no tension but carries compression", "[mpm][material][damage]") {
  ElasticDamage<2> m("coal", coal, coal_damage);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = 1.0;
  drive(m, p, l, 200, 2e-4 / 200);  // past eta eps_t0: fully damaged
  CHECK(p.damage[0] == 1.0);
  CHECK(p.stress[0].norm() == 0.0);
  CHECK(p.stress_zz[0] == 0.0);
  // Push it back into compression: the damage stays, the fragments bear the load.
  l(0, 0) = -1.0;
  drive(m, p, l, 300, 3e-4 / 300);
  CHECK(p.damage[0] == 1.0);
  const double p_modulus = coal.lame_lambda() + 2 * coal.shear_modulus();
  CHECK(p.stress[0](0, 0) == Approx(-p_modulus * 1e-4).epsilon(1e-9));
  CHECK(p.stress[0](1, 1) == Approx(-coal.lame_lambda() * 1e-4).epsilon(1e-9));
}

TEST_CASE("elastic-damage: damage never heals on unloading", "[mpm][material][damage]") {
  ElasticDamage<2> m("coal", coal, coal_damage);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = 1.0;
  drive(m, p, l, 100, 4e-5 / 100);
  const double reached = p.damage[0];
  REQUIRE(reached > 0);
  l(0, 0) = -1.0;
  drive(m, p, l, 100, 3e-5 / 100);
  CHECK(p.damage[0] == reached);
}

TEST_CASE("elastic-damage: shear damage weakens toward the friction cone", "[mpm][material][damage]") {
  ElasticDamage<2> m("coal", coal, coal_damage);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = -1.0;
  l(1, 1) = 0.9;
  drive(m, p, l, 2000, 2e-3 / 2000);
  CHECK(p.damage[0] > 0.5);
  // The stress acting lies inside the cone of the remaining cohesion.
  DruckerPrager<2> remaining("left", coal, (1 - p.damage[0]) * 1e6, 30 * deg, 0.0, DruckerPragerFit::Kind::outer);
  CHECK(remaining.yield(p.stress[0], p.stress_zz[0]) <= 1e-6 * 1e6);
  CHECK(p.plastic_strain[0] > 0);
}

TEST_CASE("elastic-damage: the work done equals the energy stored plus the energy the cracks took",
          "[mpm][material][damage][energy]") {
  // Pull in uniaxial strain through damage to full damage, then shear and
  // compress the fragments: at every step the stress power integrated so far
  // must match the stored energy plus the damage and plastic dissipation.
  ElasticDamage<2> m("coal", coal, coal_damage);
  auto p = one_particle();
  const std::vector<int> members{0};
  const auto power = [&](const Mat<2>& l) { return p.volume[0] * p.stress[0].cwiseProduct(l).sum(); };
  double work = 0;
  Dissipation dissipated;
  const auto drive_tracking = [&](const Mat<2>& l, int steps, double dt) {
    p.velocity_gradient[0] = l;
    for (int s = 0; s < steps; ++s) {
      const double before = power(l);
      dissipated += m.update_stress(p, members, dt);
      work += 0.5 * (before + power(l)) * dt;
    }
  };
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = 1.0;
  drive_tracking(l, 4000, 6e-5 / 4000);  // partly damaged
  const double partly = p.damage[0];
  CHECK(dissipated.damage > 0);
  CHECK(m.strain_energy(p, members) + dissipated.damage == Approx(work).epsilon(1e-3));
  drive_tracking(l, 4000, 2e-4 / 4000);  // fully damaged: nothing stored, all released
  CHECK(p.damage[0] == 1.0);
  CHECK(m.strain_energy(p, members) == 0.0);
  CHECK(dissipated.damage == Approx(work).epsilon(1e-3));
  CAPTURE(partly);
  // Back into compression with shear: the fragments store and rub.
  l << -1.0, 0.3, 0.0, 0.2;
  drive_tracking(l, 4000, 1e-3 / 4000);
  CHECK(dissipated.plastic > 0);
  CHECK(m.strain_energy(p, members) + dissipated.damage + dissipated.plastic == Approx(work).epsilon(2e-3));
}

TEST_CASE("elastic-damage: broken coal bulks to its bulking factor and no further", "[mpm][material][damage]") {
  ElasticDamage<2> m("coal", coal, coal_damage);
  auto p = one_particle();
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = 1.0;
  drive(m, p, l, 100, 2e-4 / 100);  // fully damaged
  REQUIRE(p.damage[0] == 1.0);
  drive(m, p, l, 100, 1.0 / 100);  // fragments parting: the deformation says 2.7 x the volume
  CHECK(p.deformation[0].determinant() > 2.5);
  CHECK(p.volume[0] == Approx(coal_damage.bulking_factor * p.volume0[0]).epsilon(1e-12));
}

namespace {

// The stress acting at damage 1 - kept: the tensile principal parts of
// `effective` scaled by kept, from an eigendecomposition of the test's own.
Mat<2> cracked(const Mat<2>& effective, double kept) {
  const Eigen::SelfAdjointEigenSolver<Mat<2>> axes(effective);
  const Vec<2> values = axes.eigenvalues().unaryExpr([&](double v) { return v > 0 ? kept * v : v; });
  return axes.eigenvectors() * values.asDiagonal() * axes.eigenvectors().transpose();
}

// Over one update of particles whose trial is `trial`: each particle of
// `after` whose damage did not grow and that slid must have the stress and
// the plastic strain of drucker_prager_return (with no dilation) applied to
// its trial's acting stress (cracked), and where no damage grew, the
// update's plastic work (`plastic`) must be the sum of the returns' works.
// Returns how many slid.
int check_slides(const ElasticDamage<2>& m, const DamageParameters& d, const Particles<2>& trial,
                 const Particles<2>& after, const std::vector<double>& damage_before,
                 const std::vector<double>& slid_before, double plastic) {
  int slid = 0;
  bool grew = false;
  double work_sum = 0, scale_sum = 0;
  for (std::size_t k = 0; k < after.size(); ++k) {
    grew = grew || after.damage[k] != damage_before[k];
    if (after.damage[k] != damage_before[k] || after.plastic_strain[k] == slid_before[k]) continue;
    CAPTURE(k);
    ++slid;
    const double stiffness = d.heterogeneity ? trial.modulus_scale[k] : 1.0;
    const double strength = d.heterogeneity ? trial.strength_scale[k] : 1.0, kept = 1 - after.damage[k];
    Mat<2> s = cracked(trial.effective_stress[k], kept);
    const double zz = trial.effective_stress_zz[k];
    double s_zz = zz > 0 ? kept * zz : zz;
    const auto [alpha, cohesion] =
        DruckerPragerFit::coefficients(DruckerPragerFit::Kind::outer, kept * strength * d.cohesion, d.friction_angle);
    const double g = stiffness * m.shear_modulus(), bulk = stiffness * m.lame_lambda() + 2.0 / 3.0 * g;
    double work = 0;
    const double multiplier = drucker_prager_return<2>(alpha, cohesion, 0.0, g, bulk, s, s_zz, &work);
    const double size = s.norm() + std::abs(s_zz);
    CHECK(multiplier > 0);
    CHECK((after.stress[k] - s).norm() <= 1e-9 * size);
    CHECK(std::abs(after.stress_zz[k] - s_zz) <= 1e-9 * size);
    CHECK(std::abs(after.plastic_strain[k] - slid_before[k] - multiplier / std::sqrt(3.0)) <= 1e-9 * size / g);
    work_sum += trial.volume[k] * work;
    scale_sum += trial.volume[k] * size * size / g;
  }
  if (!grew) CHECK(std::abs(plastic - work_sum) <= 1e-9 * scale_sum);
  return slid;
}

}  // namespace

TEST_CASE("elastic-damage: a chunk settled over SIMD lanes ends as each of its particles settled alone",
          "[mpm][material][damage]") {
  // 64 particles (a whole chunk) strained along their own paths through
  // every branch of the update: intact, equal principal stresses (no axes),
  // tensile damage growing and full, crushing, friction on the cone, and
  // unloading. Updated together, the lanes run vector code and pick the
  // particles that need settle's scalar path (the last steps with every
  // other particle, members the lanes reach through their list); updated
  // one at a time, the same code runs on a single lane. The two must agree
  // to the bit, but for the acting stress and, once friction has returned
  // it, the effective stress and the plastic strain: the compiler's fused
  // multiply-adds (placed apart in vector and scalar code) may move them by
  // an ulp, which the return's sum of a mean and a deviator of nearly
  // opposite size makes 1e-15 of the stress a few times over. And over the
  // last step, whichever path took a particle, its damage must be the law's
  // (the public, scalar form) and, where it did not slide, its acting stress
  // its effective one with the tensile principal parts scaled by 1 - D (an
  // eigendecomposition of its own). At every step, each particle that slid
  // without cracking further must have what the public return gives its
  // trial (check_slides).
  const auto run = [](const DamageParameters& d) {
    ElasticDamage<2> m("coal", coal, d);
    const int n = chunk_size;
    Particles<2> together;
    for (int k = 0; k < n; ++k) together.add({0.1 * k, 0}, {0, 0}, 1, 1, 0.25, Mat<2>::Zero(), 0, 0);
    std::vector<int> members(n);
    std::iota(members.begin(), members.end(), 0);
    m.create_fields(together, members);
    together.need_velocity_gradients();
    // Eight amplitudes: strains from 2e-5 to 3.5e-4 along each direction.
    std::vector<Mat<2>> l = own_paths(n);
    l[0].setZero();                // never loaded: principal values equal
    l[1] = Mat<2>::Identity();     // spreading equally: in tension, no axes
    l[2] = -Mat<2>::Identity();    // squeezed equally
    Particles<2> alone = together;
    Dissipation in_chunk, one_by_one;
    int slid_alone = 0;
    std::vector<int> evens, odds;
    for (int k = 0; k < n; ++k) (k % 2 ? odds : evens).push_back(k);
    std::vector<double> damage_before, slid_before;
    // Out to strains of 4e-4 (full damage at 1.7e-4 in tension), then back by a quarter.
    for (const double sign : {1.0, 1.0, -0.5}) {
      for (int k = 0; k < n; ++k) together.velocity_gradient[k] = alone.velocity_gradient[k] = sign * l[k];
      for (int s = 0; s < 100; ++s) {
        damage_before = together.damage;
        slid_before = together.plastic_strain;
        // The reference for the particles that slide without cracking
        // further: the public return applied to the trial's acting stress.
        Particles<2> trial = together;
        deform_and_trial(trial, std::span<const int>(members), 2e-6, m.lame_lambda(), m.shear_modulus(),
                         d.heterogeneity ? &trial.modulus_scale : nullptr, trial.effective_stress,
                         trial.effective_stress_zz);
        const double plastic_before = in_chunk.plastic;
        if (sign > 0) {
          in_chunk += m.update_stress(together, members, 2e-6);
        } else {
          in_chunk += m.update_stress(together, evens, 2e-6);
          in_chunk += m.update_stress(together, odds, 2e-6);
        }
        for (int k = 0; k < n; ++k) one_by_one += m.update_stress(alone, {k}, 2e-6);
        slid_alone += check_slides(m, d, trial, together, damage_before, slid_before,
                                   in_chunk.plastic - plastic_before);
      }
    }
    CHECK(slid_alone > 0);
    int damaged = 0, broken = 0, sliding = 0;
    for (int k = 0; k < n; ++k) {
      CAPTURE(k);
      const double stiffness = d.heterogeneity ? together.modulus_scale[k] : 1.0;
      const double strength = d.heterogeneity ? together.strength_scale[k] : 1.0;
      const Mat<2>& effective = together.effective_stress[k];
      const double effective_zz = together.effective_stress_zz[k], kept = 1 - together.damage[k];
      if (together.plastic_strain[k] == slid_before[k]) {
        CHECK(together.damage[k] ==
              Approx(m.damage(damage_before[k], effective, effective_zz, strength, stiffness)).margin(1e-14));
        const Mat<2> acting = cracked(effective, kept);
        CHECK((together.stress[k] - acting).norm() <= 1e-12 * effective.norm());
        CHECK(together.stress_zz[k] == (effective_zz > 0 ? kept * effective_zz : effective_zz));
      }
      const bool slid = alone.plastic_strain[k] > 0;  // at any step: the ulps stay
      const double ulps = slid ? 1e-13 : 1e-15;
      CHECK((together.stress[k] - alone.stress[k]).norm() <= ulps * alone.stress[k].norm());
      CHECK(std::abs(together.stress_zz[k] - alone.stress_zz[k]) <= (slid ? ulps * alone.stress[k].norm() : 0.0));
      CHECK((together.effective_stress[k] - alone.effective_stress[k]).norm() <=
            (slid ? ulps * alone.effective_stress[k].norm() : 0.0));
      CHECK(together.damage[k] == alone.damage[k]);
      CHECK(together.plastic_strain[k] == Approx(alone.plastic_strain[k]).epsilon(slid ? 1e-12 : 0.0));
      CHECK(together.volume[k] == alone.volume[k]);
      // Settle's friction, whichever path took the particle: a compressive
      // state within the cone of the cohesion its damage leaves.
      const double scale = d.heterogeneity ? together.strength_scale[k] : 1.0;
      const DruckerPrager<2> left("left", coal, (1 - together.damage[k]) * scale * d.cohesion,
                                  d.friction_angle, 0.0, DruckerPragerFit::Kind::outer);
      if (together.stress[k].trace() + together.stress_zz[k] < 0)
        CHECK(left.yield(together.stress[k], together.stress_zz[k]) <= 1e-9 * d.cohesion);
      damaged += together.damage[k] > 0 && together.damage[k] < 1;
      broken += together.damage[k] == 1;
      sliding += together.plastic_strain[k] > 0;
    }
    // The paths reach every branch they are meant to.
    CHECK(damaged > 0);
    CHECK(broken > 0);
    CHECK(sliding > 0);
    CHECK(together.damage[0] == 0);
    CHECK(together.damage[1] == 1);
    CHECK(together.damage[2] == 0);
    CHECK(in_chunk.damage == Approx(one_by_one.damage).epsilon(1e-12));
    CHECK(in_chunk.plastic == Approx(one_by_one.plastic).epsilon(1e-12));
  };
  // Each of the lanes' four forms: the paper's law or a crack band, uniform
  // or heterogeneous coal.
  DamageParameters band = coal_damage;
  band.fracture_energy = 2.4;
  band.band_width = 0.5;
  for (DamageParameters d : {coal_damage, band}) {
    for (const bool drawn : {false, true}) {
      if (drawn) d.heterogeneity = DamageParameters::Heterogeneity{3.0, 7};
      INFO((d.fracture_energy ? "crack band" : "the paper's law") << (drawn ? ", heterogeneous" : ", uniform"));
      run(d);
    }
  }
}

// Kolmogorov-Smirnov distance of draws u (sorted in place) to the Weibull law
// of shape m and mean 1, and the shape fitted to ln(-ln(1 - F)) = m ln u -
// m ln u0 (a Weibull plot).
std::pair<double, double> weibull_fit(std::vector<double>& u, double m) {
  std::sort(u.begin(), u.end());
  const int n = static_cast<int>(u.size());
  const double u0 = 1 / std::tgamma(1 + 1 / m);
  double ks = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < n; ++k) {
    const double f = 1 - std::exp(-std::pow(u[k] / u0, m));
    ks = std::max({ks, std::abs(f - double(k) / n), std::abs(f - double(k + 1) / n)});
    const double empirical = (k + 0.5) / n, x = std::log(u[k]), y = std::log(-std::log(1 - empirical));
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return {ks, (n * sxy - sx * sy) / (n * sxx - sx * sx)};
}

TEST_CASE("elastic-damage: stresses whose squares fall below the normal numbers keep finite principal axes, over "
          "lanes and alone",
          "[mpm][material][damage]") {
  // A body at rest under gravity carries, far from its corners, shear and
  // stress differences of 1e-160 and less: the grid's round-off, spread a
  // cell a step. Their squares are subnormal or zero, and the principal
  // radius then came out below |half the difference| for some: the
  // half-angle roots turned NaN, and a benchmark's falling block, built for
  // plain x86-64, blew up in 52 steps. No velocity gradient: the trial is the
  // stress itself, too small to damage anything.
  ElasticDamage<2> m("coal", coal, coal_damage);
  Particles<2> p;
  std::vector<Mat<2>> given;
  for (const double half : {0.0, 1e-170, 3e-162, 1e-160, 7e-158, 1e-155})
    for (const double shear : {0.0, 1e-175, 1e-170, 3e-163, 1e-160, 1e-155})
      for (const double sign : {1.0, -1.0}) {
        Mat<2> s;
        s << sign * half, shear, shear, -sign * half;
        given.push_back(s);
      }
  for (std::size_t k = 0; k < given.size(); ++k)
    p.add({0.1 * static_cast<double>(k), 0}, {0, 0}, 1, 1, 0.25, Mat<2>::Zero(), 0, 0);
  std::vector<int> members(given.size());
  std::iota(members.begin(), members.end(), 0);
  m.create_fields(p, members);
  p.need_velocity_gradients();
  for (std::size_t k = 0; k < given.size(); ++k) p.effective_stress[k] = p.stress[k] = given[k];
  Particles<2> alone = p;
  m.update_stress(p, members, 1e-6);  // a whole chunk and part of one, over lanes
  for (int k : members) m.update_stress(alone, {k}, 1e-6);
  // The squares keep too few bits for the decomposition to give back the
  // stress to its own digits: it must stay finite and as small as it was.
  int bad = 0;
  for (int k : members) {
    CAPTURE(k, given[k](0, 0), given[k](0, 1));
    const double largest = given[k].cwiseAbs().maxCoeff();
    for (const Particles<2>* q : {&p, &alone}) {
      bad += !q->stress[k].allFinite() || !q->effective_stress[k].allFinite();
      CHECK(q->damage[k] == 0);
      CHECK(q->stress[k].cwiseAbs().maxCoeff() <= 2 * largest);
    }
  }
  CHECK(bad == 0);
  CHECK(given.size() > static_cast<std::size_t>(chunk_size));
}

TEST_CASE("heterogeneous coal: strength and modulus factors follow the Weibull laws of their homogeneity indices, "
          "mean 1, independent of each other and set by the seed alone",
          "[mpm][material][damage][heterogeneity]") {
  const double shape = GENERATE(1.5, 3.0, 6.0);
  const double modulus_shape = 2 * shape;
  const DamageParameters::Heterogeneity h{shape, 7, modulus_shape}, other{shape, 8, modulus_shape};
  const int n = 20000;
  std::vector<double> strength(n), modulus(n);
  int same_as_other_seed = 0;
  for (int id = 0; id < n; ++id) {
    strength[id] = weibull_strength_scale(h, id);
    modulus[id] = weibull_modulus_scale(h, id);
    // Functions of the seed and the id only.
    REQUIRE(strength[id] == weibull_strength_scale(h, id));
    REQUIRE(modulus[id] == weibull_modulus_scale(h, id));
    same_as_other_seed += strength[id] == weibull_strength_scale(other, id);
    same_as_other_seed += modulus[id] == weibull_modulus_scale(other, id);
  }
  // Without a modulus index of its own, the moduli take the strengths'.
  CHECK(weibull_modulus_scale({shape, 7}, 5) == weibull_modulus_scale({shape, 7, shape}, 5));
  double mean_s = 0, mean_e = 0, s_e = 0, s_s = 0, e_e = 0;
  for (int k = 0; k < n; ++k) {
    mean_s += strength[k] / n, mean_e += modulus[k] / n;
    s_e += strength[k] * modulus[k] / n, s_s += strength[k] * strength[k] / n, e_e += modulus[k] * modulus[k] / n;
  }
  const double correlation = (s_e - mean_s * mean_e) / std::sqrt((s_s - mean_s * mean_s) * (e_e - mean_e * mean_e));
  auto [ks_s, fitted_s] = weibull_fit(strength, shape);
  auto [ks_e, fitted_e] = weibull_fit(modulus, modulus_shape);
  std::printf("\nWeibull m = %g: strengths' mean %.4f, fitted shape %.3f, KS distance %.4f; moduli (m_E = %g) mean "
              "%.4f, fitted %.3f, KS %.4f; correlation %.4f; %d of %d draws equal under another seed\n",
              shape, mean_s, fitted_s, ks_s, modulus_shape, mean_e, fitted_e, ks_e, correlation, same_as_other_seed,
              2 * n);
  CHECK(mean_s == Approx(1).epsilon(0.015));
  CHECK(mean_e == Approx(1).epsilon(0.015));
  CHECK(fitted_s == Approx(shape).epsilon(0.03));
  CHECK(fitted_e == Approx(modulus_shape).epsilon(0.03));
  CHECK(ks_s < 1.63 / std::sqrt(double(n)));  // the 1 % critical value
  CHECK(ks_e < 1.63 / std::sqrt(double(n)));
  CHECK(std::abs(correlation) < 2.58 / std::sqrt(double(n)));  // uncorrelated, at 1 %
  CHECK(same_as_other_seed == 0);
}

TEST_CASE("heterogeneous coal: a particle's damage starts at its own share of the strength, and only its material's "
          "particles are drawn", "[mpm][material][damage][heterogeneity]") {
  DamageParameters d = coal_damage;
  d.heterogeneity = DamageParameters::Heterogeneity{3.0, 11};
  ElasticDamage<2> m("coal", coal, d);
  // Uniaxial tension at 0.6 f_t: intact at a factor of 1, damaged at 0.5.
  Mat<2> s = Mat<2>::Zero();
  s(0, 0) = 0.6 * d.tensile_strength;
  CHECK(m.damage(0, s, 0, 1.0) == 0);
  CHECK(m.damage(0, s, 0, 0.5) > 0);
  // The factor scales the whole tensile law: D(scale eps) at scale equals D(eps) at 1.
  Mat<2> at_one = Mat<2>::Zero(), at_half = Mat<2>::Zero();
  at_one(0, 0) = 1.5 * d.tensile_strength;
  at_half(0, 0) = 0.75 * d.tensile_strength;
  CHECK(m.damage(0, at_half, 0, 0.5) == Approx(m.damage(0, at_one, 0, 1.0)).epsilon(1e-12));

  Particles<2> p;
  for (int k = 0; k < 6; ++k) p.add({0, 0}, {0, 0}, 1, 1, 0.5, Mat<2>::Zero(), 0, k % 2);
  m.create_fields(p, {1, 3, 5});
  for (int k = 0; k < 6; ++k) {
    CHECK(p.strength_scale[k] == (k % 2 ? weibull_strength_scale(*d.heterogeneity, p.id[k]) : 1.0));
    CHECK(p.modulus_scale[k] == (k % 2 ? weibull_modulus_scale(*d.heterogeneity, p.id[k]) : 1.0));
  }
}

TEST_CASE("heterogeneous coal with a grain size: particles share their grain's draws, at every spacing",
          "[mpm][material][damage][heterogeneity]") {
  DamageParameters d = coal_damage;
  d.heterogeneity = DamageParameters::Heterogeneity{3.0, 5, std::nullopt, 0.25};
  ElasticDamage<2> m("coal", coal, d);
  // Two fills of the same 2 m x 1 m block, below and right of the origin,
  // at spacings of 1/12 and 1/16 m (1/6 and 1/8 m cells, 4 per cell): the
  // factors at a point are its grain's, whichever fill it is in.
  std::map<std::pair<int, int>, std::pair<double, double>> grains;
  int grains_seen_twice = 0;
  for (const int per_metre : {12, 16}) {
    Particles<2> p;
    std::vector<int> members;
    for (int i = 0; i < 2 * per_metre; ++i)
      for (int j = 0; j < per_metre; ++j) {
        const Vec<2> x((i + 0.5) / per_metre - 1.0, (j + 0.5) / per_metre - 1.0);
        members.push_back(static_cast<int>(p.size()));
        p.add(x, {0, 0}, 1, 1, 0.5, Mat<2>::Zero(), 0, 0);
      }
    m.create_fields(p, members);
    for (const int k : members) {
      const std::pair<int, int> grain{static_cast<int>(std::floor(p.x0[k][0] / 0.25)),
                                      static_cast<int>(std::floor(p.x0[k][1] / 0.25))};
      const auto [at, first] = grains.try_emplace(grain, p.strength_scale[k], p.modulus_scale[k]);
      CHECK(p.strength_scale[k] == at->second.first);
      CHECK(p.modulus_scale[k] == at->second.second);
      grains_seen_twice += per_metre == 16 && !first;
    }
  }
  REQUIRE(grains.size() == 8 * 4);
  CHECK(grains_seen_twice > 0);
  // Grains draw apart: no two of the 32 share a factor.
  std::set<double> strengths;
  for (const auto& [grain, factors] : grains) strengths.insert(factors.first);
  CHECK(strengths.size() == grains.size());
  // Without a grain size each particle draws its own, by id.
  CHECK(DamageParameters::Heterogeneity{3.0, 5}.key(17, Vec<2>(0.1, 0.1)) == 17);
  CHECK(d.heterogeneity->key(17, Vec<2>(0.1, 0.1)) == d.heterogeneity->key(18, Vec<2>(0.2, 0.2)));
  CHECK(d.heterogeneity->key(17, Vec<2>(0.1, 0.1)) != d.heterogeneity->key(17, Vec<2>(-0.1, 0.1)));
}

TEST_CASE("heterogeneous coal: a particle's modulus factor sets its wave speed, and the stiffest sets the stable step",
          "[mpm][material][damage][heterogeneity]") {
  DamageParameters d = coal_damage;
  d.heterogeneity = DamageParameters::Heterogeneity{1.5, 3};
  std::vector<std::unique_ptr<Material<2>>> materials;
  materials.push_back(std::make_unique<ElasticDamage<2>>("coal", coal, d));
  Particles<2> p;
  for (int k = 0; k < 4000; ++k) p.add({0, 0}, {0, 0}, coal.density, 1, 0.5, Mat<2>::Zero(), 0, 0);
  std::vector<int> all(p.size());
  for (int k = 0; k < 4000; ++k) all[k] = k;
  const double uniform_step = stable_time_step(materials, p, 0.1, 0.5);
  materials[0]->create_fields(p, all);
  const double stiffest = *std::max_element(p.modulus_scale.begin(), p.modulus_scale.end());
  REQUIRE(stiffest > 3);  // m = 1.5: a wide spread
  CHECK(stable_time_step(materials, p, 0.1, 0.5) == Approx(uniform_step / std::sqrt(stiffest)).epsilon(1e-12));
  CHECK(uniform_step == Approx(0.5 * 0.1 / coal.p_wave_speed()).epsilon(1e-12));

  // Uniaxial strain in one particle: its stress is the stiffness times the
  // uniform coal's (below the strength, so undamaged).
  auto one = one_particle();
  one.need("heterogeneity");
  one.strength_scale[0] = 1, one.modulus_scale[0] = 0.4;
  Mat<2> l = Mat<2>::Zero();
  l(0, 0) = -1e-5;
  drive(*materials[0], one, l, 10, 0.1);
  CHECK(one.stress[0](0, 0) == Approx(-0.4 * (coal.lame_lambda() + 2 * coal.shear_modulus()) * 1e-5).epsilon(1e-9));
  CHECK(one.damage[0] == 0);
  // Its strain energy with its own compliance: sigma eps / 2.
  CHECK(materials[0]->strain_energy(one, {0}) ==
        Approx(0.5 * -one.stress[0](0, 0) * 1e-5 * one.volume[0]).epsilon(1e-6));
}

TEST_CASE("heterogeneous coal: a particle s_E times as stiff, strained 1 / s_E as much, carries the same stress, "
          "damage and friction, with 1 / s_E the plastic strain and work", "[mpm][material][damage][heterogeneity]") {
  DamageParameters d = coal_damage;
  d.heterogeneity = DamageParameters::Heterogeneity{3.0, 1};
  const ElasticDamage<2> m("coal", coal, d);
  // Pure shear under a little compression (no spin: the Jaumann rotation goes
  // with the strain, not the moduli): into the friction cone and past the
  // shear damage's onset.
  Mat<2> l;
  l << -2e-5, 1e-4, 1e-4, -2e-5;
  const double stiffness = 2.5;
  Particles<2> uniform = one_particle(), stiff = one_particle();
  for (Particles<2>* p : {&uniform, &stiff}) {
    p->need("heterogeneity");
    p->strength_scale[0] = 1;
  }
  uniform.modulus_scale[0] = 1;
  stiff.modulus_scale[0] = stiffness;
  Dissipation by_uniform, by_stiff;
  for (int s = 0; s < 400; ++s) {
    uniform.velocity_gradient[0] = l;
    stiff.velocity_gradient[0] = l / stiffness;
    by_uniform += m.update_stress(uniform, {0}, 0.1);
    by_stiff += m.update_stress(stiff, {0}, 0.1);
  }
  REQUIRE(uniform.plastic_strain[0] > 0);
  REQUIRE(uniform.damage[0] > 0);
  CHECK((stiff.stress[0] - uniform.stress[0]).norm() < 1e-6 * uniform.stress[0].norm());
  CHECK(stiff.damage[0] == Approx(uniform.damage[0]).epsilon(1e-6));
  CHECK(stiff.plastic_strain[0] == Approx(uniform.plastic_strain[0] / stiffness).epsilon(1e-6));
  // The volumes differ by the strains' difference: compare work per volume.
  CHECK(by_stiff.plastic / stiff.volume[0] ==
        Approx(by_uniform.plastic / uniform.volume[0] / stiffness).epsilon(1e-3));
}

TEST_CASE("crack band: a material point dissipates G_f per band width whatever holds its sides, and s_f^2 / s_E times as "
          "much with factors s_f, s_E on its strength and moduli", "[mpm][material]") {
  // nu = 0.4 (Table 1), a band at 90 % of the snap-back limit: the onset's
  // share of the energy is large, and (lambda + 2G) / E = 2.14.
  DamageParameters d{1e6, 30 * deg, 0.2e6, 0.1, 5.0, 2.4};
  d.band_width = 0.9 * largest_band_width(d, coal);
  const ElasticDamage<2> uniform("coal", coal, d);
  d.heterogeneity = DamageParameters::Heterogeneity{3.0, 1};
  const ElasticDamage<2> drawn("coal", coal, d);
  // A weak, soft particle and a strong, stiff one: each keeps its
  // characteristic length, so the band stays within its snap-back limit.
  const auto [strength, stiffness] = GENERATE(std::pair{1.0, 1.0}, std::pair{0.6, 0.5}, std::pair{1.7, 2.2});
  const bool heterogeneous = strength != 1.0;
  const Material<2>& m = heterogeneous ? static_cast<const Material<2>&>(drawn) : uniform;
  const double per_volume = strength * strength / stiffness * *d.fracture_energy / d.band_width;
  // Stretched along x with y held (uniaxial strain: the intact coal holds a
  // crack's sides) and with y free (uniaxial stress in the plane: the bar).
  const double lambda = stiffness * coal.lame_lambda(), modulus = lambda + 2 * stiffness * coal.shear_modulus();
  for (const bool held : {true, false}) {
    auto p = one_particle();
    if (heterogeneous) {
      p.need("heterogeneity");
      p.strength_scale[0] = strength;
      p.modulus_scale[0] = stiffness;
    }
    double dissipated = 0;
    const double dt = 1e-3, rate = 1e-9 / dt;  // eps_xx grows by 1e-9 a step
    for (int s = 0; s < 2000000 && p.damage[0] < 1; ++s) {
      Mat<2> l = Mat<2>::Zero();
      l(0, 0) = rate;
      // Free: the lateral rate that keeps the undamaged sigma_yy, and with
      // it the acting one, at zero.
      if (!held) l(1, 1) = -(lambda * rate + p.effective_stress[0](1, 1) / dt) / modulus;
      p.velocity_gradient[0] = l;
      const Dissipation r = m.update_stress(p, {0}, dt);
      dissipated += r.damage + r.plastic;
    }
    INFO((held ? "sides held" : "sides free") << ", s_f = " << strength << ", s_E = " << stiffness);
    CHECK(p.damage[0] == 1.0);
    CHECK(dissipated / p.volume[0] == Approx(per_volume).epsilon(0.01));
  }
}
