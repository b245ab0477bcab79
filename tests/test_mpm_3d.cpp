// The MPM solver in 3D: the same code as the plane one with Dim = 3.
//  - a manufactured solution varying along x, y and z converges at second
//    order under each shape function;
//  - a slab between roller walls is plane strain: it moves as the 2D solver's
//    body does, particle for particle, for elastic, plastic and damaging
//    material, and under every load, contact and velocity transfer;
//  - a column under gravity settles to the stress its weight gives;
//  - the grid's passes stay within the blocks the particles reach.
#include <catch2/catch.hpp>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <ostream>
#include <utility>

#include "convergence.hpp"
#include "mpm_fixtures.hpp"
#include "mpm_solid/materials/drucker_prager.hpp"
#include "mpm_solid/materials/elastic_damage.hpp"
#include "mpm_solid/shape.hpp"
#include "mpm_solid/stencil.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

namespace {

constexpr double pi = 3.14159265358979323846;

// u_i = A sin(pi t) phi for every component i, phi = sin(pi X) sin(pi Y)
// sin(pi Z) on the unit cube, fixed on all six faces; the body force
// b_i = rho u_i,tt - mu lap u_i - (lambda + mu) d_i div u drives it.
// Fixed Courant number: the step's error falls with h^2 as the cells' does.
double manufactured_error_3d(ShapeKind shape, int cells) {
  constexpr double A = 1e-6, rho = 1.0, E = 1.0, nu = 0.25;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double h = 1.0 / cells;
  const Grid<3> g = grid(Vec<3>(1, 1, 1), h);
  Particles<3> p = block<3>(g, Vec<3>::Zero(), Vec<3>::Ones(), rho, 2);
  const auto phi = [](const Vec<3>& x) { return std::sin(pi * x[0]) * std::sin(pi * x[1]) * std::sin(pi * x[2]); };
  for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = Vec<3>::Constant(A * pi * phi(p.x[i]));
  Settings<3> s;
  s.shape = shape;
  s.flip_fraction = 1.0;
  for (auto& w : s.walls) w = Wall{Wall::Type::fixed};
  Solver<3> solver(g, elastic<3>({rho, E, nu}), std::move(p), s);
  // The body force per unit amplitude sin(pi t): sum_j phi_ij along each i.
  const auto& q = solver.particles();
  std::vector<Vec<3>> force_shape(q.size());
  for (std::size_t k = 0; k < q.size(); ++k) {
    const Vec<3> x = q.x0[k] * pi;
    const Vec<3> sn(std::sin(x[0]), std::sin(x[1]), std::sin(x[2])), cs(std::cos(x[0]), std::cos(x[1]), std::cos(x[2]));
    Mat<3> hessian;  // phi_ij / pi^2
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double v = 1;
        for (int d = 0; d < 3; ++d) v *= (d == i) != (d == j) ? cs[d] : sn[d];
        hessian(i, j) = i == j ? -sn.prod() : v;
      }
    const double f = sn.prod();
    for (int i = 0; i < 3; ++i)
      force_shape[k][i] = A * pi * pi * (3 * mu * f - (lambda + mu) * hessian.row(i).sum() - rho * f);
  }
  const double end = 1.0, dt = 0.1 * h;
  const int steps = static_cast<int>(std::lround(end / dt));
  double worst = 0;
  for (int n = 0; n < steps; ++n) {
    const double amplitude = std::sin(pi * solver.time());
    for (std::size_t k = 0; k < q.size(); ++k) solver.external_force()[k] = q.volume0[k] * amplitude * force_shape[k];
    solver.step(dt);
    if ((n + 1) % (steps / 4) != 0) continue;
    double sum = 0;
    for (std::size_t k = 0; k < q.size(); ++k) {
      const Vec<3> exact = Vec<3>::Constant(A * std::sin(pi * solver.time()) * phi(q.x0[k]));
      sum += (q.x[k] - q.x0[k] - exact).squaredNorm();
    }
    worst = std::max(worst, std::sqrt(sum / static_cast<double>(q.size())) / A);
  }
  return worst;
}

}  // namespace

TEST_CASE("3D: the full scheme converges at second order on a manufactured solution varying along x, y and z",
          "[mpm][3d][mms]") {
  for (auto [shape, name] : {std::pair{ShapeKind::linear, "linear"}, std::pair{ShapeKind::gimp, "GIMP"},
                             std::pair{ShapeKind::bspline, "B-spline"}}) {
    std::vector<ConvergenceRow> rows;
    for (int cells : {4, 8, 16}) rows.push_back({1.0 / cells, manufactured_error_3d(shape, cells)});
    print_convergence(std::string("3D MPM manufactured solution, USF, ") + name +
                          ": max RMS displacement error / A (Courant 0.1)",
                      "h", rows);
    CHECK(observed_orders(rows).back() > 1.7);
  }
}

namespace {

// The OpenMP thread count for a scope (a solver takes it when built).
struct ThreadsFor {
  int before = omp_get_max_threads();
  explicit ThreadsFor(int n) { omp_set_num_threads(n); }
  ~ThreadsFor() { omp_set_num_threads(before); }
};

enum class Model { elastic, drucker_prager, damage };

template <int Dim>
std::vector<std::unique_ptr<Material<Dim>>> model(Model m) {
  const Elasticity e{1000, 1e7, 0.3};
  std::vector<std::unique_ptr<Material<Dim>>> v;
  switch (m) {
    case Model::elastic: v.push_back(std::make_unique<LinearElastic<Dim>>("m", e)); break;
    case Model::drucker_prager:
      v.push_back(std::make_unique<DruckerPrager<Dim>>("m", e, 2e3, 0.5, 0.1, DruckerPragerFit::Kind::outer));
      break;
    case Model::damage:
      v.push_back(std::make_unique<ElasticDamage<Dim>>(
          "m", e,
          DamageParameters{.cohesion = 2e4, .friction_angle = 0.5, .tensile_strength = 3e3, .residual_ratio = 0.1,
                           .ultimate_ratio = 5, .fracture_energy = std::nullopt}));
      break;
  }
  return v;
}

// A block thrown down and sideways onto a fixed floor beside a fixed wall,
// with gravity: it deforms, yields or cracks as it lands. In 3D it fills a
// slab two cells thick between roller walls. No node is taken for empty by
// its mass alone: the layer of nodes on a wall holds half the mass an inner
// layer does (its mirror images' share is not added), so a node at the
// body's fringe crosses that threshold in one layer before the other, and
// plastic flow carries the difference on (2e-4 of the stress in 200 steps
// under B-splines); with any mass counted, the layers agree.
template <int Dim>
Settings<Dim> landing(ShapeKind shape, Scheme scheme) {
  Settings<Dim> s;
  s.empty_node_mass_fraction = 0;
  s.shape = shape;
  s.scheme = scheme;
  s.gravity = Vec<Dim>::Zero();
  s.gravity[1] = -9.81;
  s.walls[0] = Wall{Wall::Type::fixed};
  s.walls[2] = Wall{Wall::Type::fixed};
  if constexpr (Dim == 3) s.walls[4] = s.walls[5] = Wall{Wall::Type::roller};
  return s;
}


// How far a slab's particles are from the plane body's, each plane particle
// standing for a column of 3D ones across the slab (4 of them), and what
// plane strain has none of: motion along z, shear across the slab.
struct SlabDifference {
  double position = 0, velocity = 0, stress = 0, out_of_plane = 0, damage = 0, across = 0;
  double scale = 0;  // the largest plane stress [Pa]
};

SlabDifference slab_against_plane(const Particles<2>& a, const Particles<3>& b, bool damage) {
  REQUIRE(b.size() == 4 * a.size());
  std::map<std::pair<long, long>, std::size_t> by_start;
  for (std::size_t i = 0; i < a.size(); ++i)
    by_start[{std::lround(a.x0[i].x() * 1e6), std::lround(a.x0[i].y() * 1e6)}] = i;
  SlabDifference d;
  for (std::size_t j = 0; j < b.size(); ++j) {
    const std::size_t i = by_start.at({std::lround(b.x0[j].x() * 1e6), std::lround(b.x0[j].y() * 1e6)});
    d.position = std::max(d.position, (b.x[j].head<2>() - a.x[i]).norm());
    d.velocity = std::max(d.velocity, (b.v[j].head<2>() - a.v[i]).norm());
    d.stress = std::max(d.stress, (b.stress[j].topLeftCorner<2, 2>() - a.stress[i]).cwiseAbs().maxCoeff());
    d.out_of_plane = std::max(d.out_of_plane, std::abs(b.stress[j](2, 2) - a.stress_zz[i]));
    if (damage) d.damage = std::max(d.damage, std::abs(b.damage[j] - a.damage[i]));
    d.across = std::max({d.across, std::abs(b.x[j].z() - b.x0[j].z()),
                         b.stress[j].col(2).head<2>().cwiseAbs().maxCoeff() /
                             std::max(1.0, a.stress[i].cwiseAbs().maxCoeff())});
    d.scale = std::max(d.scale, a.stress[i].cwiseAbs().maxCoeff());
  }
  return d;
}

std::ostream& operator<<(std::ostream& out, const SlabDifference& d) {
  return out << "3D against plane: position " << d.position << " m, velocity " << d.velocity << " m/s, stress "
             << d.stress << " Pa, out-of-plane stress " << d.out_of_plane << " Pa, damage " << d.damage
             << "; across the slab " << d.across << "; largest stress " << d.scale << " Pa";
}
}  // namespace

// Plane strain is the 3D state with no motion along z: a slab between roller
// walls moves as the plane body, up to roundoff. Where the coal cracks or
// flows (non-associated friction), roundoff across the slab, which the plane
// body cannot carry, grows for a while (from 1e-16 to 1e-10 of the stress in
// ten steps): the bound is 1e-8 of the scales, far below what a wrong term
// would leave (the empty-node threshold alone, above, leaves 2e-4).
TEST_CASE("3D: a slab between roller walls moves as the plane-strain body does, particle for particle",
          "[mpm][3d]") {
  const Model m = GENERATE(Model::elastic, Model::drucker_prager, Model::damage);
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::bspline);
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::musl);
  const ThreadsFor one(1);
  const double h = 0.1, speed = 2.5;
  const int steps = 200;
  Particles<2> p2 = block<2>(grid(2.0, 1.5, h), Vec<2>(0, 0.1), Vec<2>(0.8, 0.7), 1000, 2);
  Particles<3> p3 = block<3>(grid(Vec<3>(2.0, 1.5, 2 * h), h), Vec<3>(0, 0.1, 0), Vec<3>(0.8, 0.7, 2 * h), 1000, 2);
  for (auto& v : p2.v) v = Vec<2>(1.5, -2.0);
  for (auto& v : p3.v) v = Vec<3>(1.5, -2.0, 0);
  Solver<2> plane(grid(2.0, 1.5, h), model<2>(m), std::move(p2), landing<2>(shape, scheme));
  Solver<3> solid(grid(Vec<3>(2.0, 1.5, 2 * h), h), model<3>(m), std::move(p3), landing<3>(shape, scheme));
  const double dt = plane.stable_time_step();
  CHECK(solid.stable_time_step() == Approx(dt).epsilon(1e-12));
  for (int k = 0; k < steps; ++k) {
    plane.step(dt);
    solid.step(dt);
  }
  const auto& a = plane.particles();
  const SlabDifference d = slab_against_plane(a, solid.particles(), m == Model::damage);
  INFO(d);
  CHECK(d.position < 1e-8 * 1.0);
  CHECK(d.velocity < 1e-8 * speed);
  CHECK(d.stress < 1e-8 * d.scale);
  CHECK(d.out_of_plane < 1e-8 * d.scale);
  CHECK(d.damage < 1e-8);
  CHECK(d.across < 1e-8);
  if (m == Model::drucker_prager) CHECK(*std::max_element(a.plastic_strain.begin(), a.plastic_strain.end()) > 0);
  if (m == Model::damage) CHECK(*std::max_element(a.damage.begin(), a.damage.end()) == 1.0);
  // The slab is two cells, 0.2 m, deep: the plane energies are per metre.
  const Energies e2 = plane.energies(), e3 = solid.energies();
  CHECK(e3.kinetic == Approx(0.2 * e2.kinetic).epsilon(1e-8));
  CHECK(e3.strain + e3.plastic + e3.damage == Approx(0.2 * (e2.strain + e2.plastic + e2.damage)).epsilon(1e-8));
  CHECK(e3.total() == Approx(0.2 * e2.total()).epsilon(1e-8).margin(1e-9 * 0.2 * e2.kinetic));
}

namespace {

// The slab of a loaded body, plane or 3D: Drucker-Prager coal holding an
// in-situ stress slides left across a friction obstacle (the floor rock)
// into a friction wall, pressed from above by a platen and from the right by
// a traction, under gravity. The 3D loads are the plane ones (per metre)
// times the slab's depth, shared among its particles as a scene's are.
template <int Dim>
Solver<Dim> loaded_slab(ShapeKind shape, bool apic) {
  const double h = 0.1, depth = 2 * h, spacing = h / 2, rock = 0.1, top = 0.7, right = 0.85;
  const Vec<2> size(2.0, 1.5);
  Grid<Dim> g;
  if constexpr (Dim == 2) g = grid(size.x(), size.y(), h);
  else g = grid(Vec<3>(size.x(), size.y(), depth), h);
  // Boxes of the plane, across the whole slab in 3D.
  auto box = [](double x, double y, double z) {
    Vec<Dim> v;
    v.template head<2>() = Vec<2>(x, y);
    if constexpr (Dim == 3) v.z() = z;
    return v;
  };
  Particles<Dim> p = block<Dim>(g, box(0.05, rock, 0), box(right, top, depth), 1000, 2);
  const double nu = 0.3, sxx = -2e4, syy = -1e4;
  p.need_loads();
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.v[i] = box(-2.0, 0, 0);
    p.stress[i].setZero();
    p.stress[i](0, 0) = sxx;
    p.stress[i](1, 1) = syy;
    if constexpr (Dim == 2) p.stress_zz[i] = nu * (sxx + syy);
    else p.stress[i](2, 2) = nu * (sxx + syy);
    // 5 kPa pushing into the right face, on its outermost layer of particles.
    if (p.x[i].x() > right - spacing) p.surface_force[i].x() = -5e3 * (Dim == 2 ? spacing : spacing * spacing);
  }
  Settings<Dim> s;
  s.empty_node_mass_fraction = 0;  // as landing's
  s.shape = shape;
  s.scheme = Scheme::usl;
  s.apic = apic;
  s.flip_fraction = 0.5;
  s.gravity = box(0, -9.81, 0);
  s.walls[0] = Wall{Wall::Type::friction, 0.3};
  if constexpr (Dim == 3) s.walls[4] = s.walls[5] = Wall{Wall::Type::roller};
  s.obstacles.push_back({box(-1, -1, -1), box(3, rock, 1), Wall{Wall::Type::friction, 0.4}});
  s.platens.push_back({box(-1, top, -1), box(3, 2, 1), 1, -2e3 * (Dim == 2 ? 1.0 : depth), std::nullopt});
  return Solver<Dim>(g, model<Dim>(Model::drucker_prager), std::move(p), s);
}

}  // namespace

// Every load and contact a scene can name, and the velocity transfers, on
// the slab: it moves as the plane body does, particle for particle.
TEST_CASE("3D: a slab under in-situ stress, a platen, a traction, friction walls and obstacles moves as the "
          "plane body does, under APIC and a FLIP/PIC blend",
          "[mpm][3d]") {
  const bool apic = GENERATE(false, true);
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::gimp, ShapeKind::bspline);
  const ThreadsFor one(1);
  Solver<2> plane = loaded_slab<2>(shape, apic);
  Solver<3> solid = loaded_slab<3>(shape, apic);
  const double dt = plane.stable_time_step();
  for (int k = 0; k < 200; ++k) {
    plane.step(dt);
    solid.step(dt);
  }
  const auto& a = plane.particles();
  const SlabDifference d = slab_against_plane(a, solid.particles(), false);
  INFO(d);
  CHECK(d.position < 1e-8 * 1.0);
  CHECK(d.velocity < 1e-8 * 2.0);
  CHECK(d.stress < 1e-8 * d.scale);
  CHECK(d.out_of_plane < 1e-8 * d.scale);
  CHECK(d.across < 1e-8);
  // Each load acted: the wall stopped the body (the floor's friction alone
  // would take 0.2 m/s of its 2 m/s), the platen moved, the coal yielded.
  double momentum = 0, mass = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    momentum += a.mass[i] * a.v[i].x();
    mass += a.mass[i];
  }
  CHECK(momentum / mass > -1.0);
  CHECK(std::abs(plane.platen_displacement()[0]) > 0.01);
  CHECK(*std::max_element(a.plastic_strain.begin(), a.plastic_strain.end()) > 0);
  const Energies e2 = plane.energies(), e3 = solid.energies();
  CHECK(e2.walls > 0);
  CHECK(std::abs(e2.external) > 0);
  CHECK(e3.kinetic == Approx(0.2 * e2.kinetic).epsilon(1e-8));
  CHECK(e3.walls == Approx(0.2 * e2.walls).epsilon(1e-8));
  CHECK(e3.external == Approx(0.2 * e2.external).epsilon(1e-8));
  CHECK(e3.total() == Approx(0.2 * e2.total()).epsilon(1e-8).margin(1e-9 * 0.2 * e2.kinetic));
}

// The volumetric-locking remedy sets each particle's dilatation rate tr(L)
// to its volume-weighted average over the nodes, interpolated back, and keeps
// L's deviatoric part. A body uniform along z between roller walls has
// L_zz = 0 before the remedy, so L before it is L after less L_zz times I:
// from one step (too short to move anything) the test rebuilds the average
// and finds it in tr(L).
TEST_CASE("3D: the nodal dilatation remedy gives each particle the averaged dilatation rate", "[mpm][3d]") {
  const ThreadsFor one(1);
  const double h = 0.1;
  const Grid<3> g = grid(Vec<3>(1.0, 1.0, 2 * h), h);
  Particles<3> p = block<3>(g, Vec<3>(0.2, 0.2, 0), Vec<3>(0.8, 0.8, 2 * h), 1000, 2);
  for (std::size_t i = 0; i < p.size(); ++i)
    p.v[i] = Vec<3>(std::sin(7 * p.x[i].y()) + p.x[i].x() * p.x[i].x(), std::cos(5 * p.x[i].x()), 0);
  Settings<3> s;
  s.shape = ShapeKind::linear;
  s.smooth_dilatation = true;
  s.walls[4] = s.walls[5] = Wall{Wall::Type::roller};
  Solver<3> solver(g, model<3>(Model::elastic), std::move(p), s);
  const Particles<3> start = solver.particles();
  solver.step(1e-12);
  const auto& q = solver.particles();
  std::vector<double> trace_before(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) trace_before[i] = q.velocity_gradient[i].trace() - 3 * q.velocity_gradient[i](2, 2);
  const Lattice<3> lattice(g);
  Stencil<3, Linear> st;
  std::map<std::size_t, std::pair<double, double>> nodes;  // sum of V tr(L), sum of V
  for (std::size_t i = 0; i < q.size(); ++i) {
    st.compute(lattice, start.x[i], start.half_width[i]);
    for (int k = 0; k < st.count; ++k) {
      nodes[st.node[k]].first += st.weight[k] * start.volume[i] * trace_before[i];
      nodes[st.node[k]].second += st.weight[k] * start.volume[i];
    }
  }
  double worst = 0, spread = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    st.compute(lattice, start.x[i], start.half_width[i]);
    double averaged = 0;
    for (int k = 0; k < st.count; ++k)
      if (const auto& [weighted, volume] = nodes.at(st.node[k]); volume > 0) averaged += st.weight[k] * weighted / volume;
    worst = std::max(worst, std::abs(q.velocity_gradient[i].trace() - averaged));
    spread = std::max(spread, std::abs(trace_before[i] - averaged));
  }
  INFO("largest |tr L - its average| " << worst << " 1/s; before the remedy " << spread << " 1/s");
  CHECK(spread > 0.1);  // the remedy had something to do
  CHECK(worst < 1e-8 * spread);
}

TEST_CASE("3D: a column settles under its weight to sigma_yy = -rho g (H - y), laterally held (K0)",
          "[mpm][3d]") {
  // 0.4 x 1 x 0.4 m of elastic material on a fixed floor, rollers on the four
  // sides, local damping to bring it to rest.
  const double h = 0.1, rho = 2000, H = 1.0, nu = 0.25;
  const Grid<3> g = grid(Vec<3>(0.4, 1.2, 0.4), h);
  Settings<3> s;
  s.gravity = Vec<3>(0, -10, 0);
  s.local_damping = 0.3;
  for (auto& w : s.walls) w = Wall{Wall::Type::roller};
  s.walls[2] = Wall{Wall::Type::fixed};
  s.walls[3] = Wall{};
  Solver<3> solver(g, elastic<3>({rho, 5e6, nu}), block<3>(g, Vec<3>::Zero(), Vec<3>(0.4, H, 0.4), rho, 2), s);
  const double dt = solver.stable_time_step();
  for (int k = 0; k < 1500; ++k) solver.step(dt);
  const auto& p = solver.particles();
  double worst = 0, lateral = 0, shear = 0, weight = rho * 10 * H;
  for (std::size_t i = 0; i < p.size(); ++i) {
    // The exact column's stress at the particle's initial height (the
    // compression, rho g H / E = 4e-3, moves it little).
    const double exact = -rho * 10 * (H - p.x0[i].y());
    worst = std::max(worst, std::abs(p.stress[i](1, 1) - exact));
    const double k0 = nu / (1 - nu);
    lateral = std::max({lateral, std::abs(p.stress[i](0, 0) - k0 * exact), std::abs(p.stress[i](2, 2) - k0 * exact)});
    shear = std::max({shear, std::abs(p.stress[i](0, 1)), std::abs(p.stress[i](0, 2)), std::abs(p.stress[i](1, 2))});
  }
  INFO("largest error over rho g H: vertical " << worst / weight << ", lateral " << lateral / weight << ", shear "
                                               << shear / weight << ", kinetic over strain energy "
                                               << solver.kinetic_energy() / solver.strain_energy());
  CHECK(worst < 0.03 * weight);
  CHECK(lateral < 0.01 * weight);
  CHECK(shear < 1e-9 * weight);
  CHECK(solver.kinetic_energy() < 1e-6 * solver.strain_energy());
}

TEST_CASE("3D: the grid's passes keep every nodal value inside the blocks the particles reach",
          "[mpm][3d][active grid]") {
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::bspline);
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::usl, Scheme::musl);
  const ThreadsFor two(2);
  // A cube thrown into the corner of fixed, roller and friction walls, on a
  // grid three times as wide as it.
  const Grid<3> g = grid(Vec<3>(1.5, 1.5, 1.5), 0.1);
  Particles<3> p = block<3>(g, Vec<3>(0.0, 0.0, 0.0), Vec<3>(0.5, 0.5, 0.5), 1000, 2);
  for (auto& v : p.v) v = Vec<3>(-1.0, -1.0, -1.0);
  Settings<3> s;
  s.shape = shape;
  s.scheme = scheme;
  s.gravity = Vec<3>(0, -9.81, 0);
  s.walls = {Wall{Wall::Type::fixed}, Wall{}, Wall{Wall::Type::friction, 0.3}, Wall{}, Wall{Wall::Type::roller},
             Wall{}};
  Solver<3> solver(g, elastic<3>({1000, 1e6, 0.3}), std::move(p), s);
  const double dt = solver.stable_time_step();
  std::size_t stray = 0;
  for (int k = 0; k < 60; ++k) {
    solver.step(dt);
    stray += solver.stray_nodal_values();
  }
  CHECK(stray == 0);
  CHECK(solver.active_nodes() < g.num_nodes() / 4);
  CHECK(std::isfinite(solver.energies().total()));
}
