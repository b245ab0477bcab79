// Contact: friction on a slope and on rigid obstacles, bodies resting on
// obstacles and supports (the settling stage), rigid platens, and the ghost
// nodes where a friction wall meets a fixed or roller one.
#include <catch2/catch.hpp>

#include <cmath>

#include "common/program.hpp"
#include "mpm_fixtures.hpp"

using namespace outburst;
using namespace outburst::mpm;
using namespace outburst::testing;

TEST_CASE("a block slides down a frictional slope at g (sin t - mu cos t)", "[mpm][friction]") {
  // The slope is the floor, with gravity tilted by theta.
  const double theta = 30 * 3.14159265358979323846 / 180, mu = 0.2, g = 9.81;
  const Grid<2> gr = grid(8.0, 2.0, 0.1);
  Settings<2> s;
  s.gravity = {g * std::sin(theta), -g * std::cos(theta)};
  s.walls[2] = {Wall::Type::friction, mu};
  Solver<2> solver(gr, elastic({1000, 5e7, 0.3}), block(gr, {0.5, 0}, {1.5, 0.5}, 1000, 2), s);
  const double t_end = 0.8;
  while (solver.time() < t_end) solver.step(std::min(solver.stable_time_step(), t_end - solver.time()));
  const auto& p = solver.particles();
  double x = 0, v = 0, m = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    x += p.mass[i] * (p.x[i].x() - p.x0[i].x());
    v += p.mass[i] * p.v[i].x();
    m += p.mass[i];
  }
  const double a = g * (std::sin(theta) - mu * std::cos(theta));
  std::printf("\nsliding block after %.2f s: displacement %.4f m (exact %.4f), velocity %.4f m/s (exact %.4f)\n",
              t_end, x / m, 0.5 * a * t_end * t_end, v / m, a * t_end);
  CHECK(v / m == Approx(a * t_end).epsilon(0.03));
  CHECK(x / m == Approx(0.5 * a * t_end * t_end).epsilon(0.03));
}

TEST_CASE("a block slides down a rigid frictional obstacle at g (sin t - mu cos t)", "[mpm][friction][obstacle]") {
  // The same slope as above, now the top face of a rigid obstacle inside the
  // grid, on a grid line or 0.45 cells above one.
  const double theta = 30 * 3.14159265358979323846 / 180, mu = 0.2, g = 9.81, h = 0.1;
  const double surface = GENERATE(0.5, 0.545);
  const Grid<2> gr = grid(8.0, 2.0, h);
  Settings<2> s;
  s.gravity = {g * std::sin(theta), -g * std::cos(theta)};
  s.obstacles.push_back({{0, 0}, {8.0, surface}, {Wall::Type::friction, mu}});
  // The particles fill the cells above the surface.
  const double base = std::ceil(surface / h - 1e-9) * h;
  Solver<2> solver(gr, elastic({1000, 5e7, 0.3}), block(gr, {0.5, base}, {1.5, base + 0.5}, 1000, 2), s);
  const double t_end = 0.8;
  const Energies start = solver.energies();
  double lowest = 1e9;
  while (solver.time() < t_end) {
    solver.step(std::min(solver.stable_time_step(), t_end - solver.time()));
    for (const auto& x : solver.particles().x) lowest = std::min(lowest, x.y());
  }
  const auto& p = solver.particles();
  double x = 0, v = 0, m = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    x += p.mass[i] * (p.x[i].x() - p.x0[i].x());
    v += p.mass[i] * p.v[i].x();
    m += p.mass[i];
  }
  const double a = g * (std::sin(theta) - mu * std::cos(theta));
  std::printf("\nblock on an obstacle (surface y = %.3f m): displacement %.4f m (exact %.4f), velocity %.4f m/s "
              "(exact %.4f), lowest particle %.4f m\n",
              surface, x / m, 0.5 * a * t_end * t_end, v / m, a * t_end, lowest);
  CHECK(v / m == Approx(a * t_end).epsilon(0.03));
  CHECK(x / m == Approx(0.5 * a * t_end * t_end).epsilon(0.03));
  // Particles sit a quarter cell above the lowest grid line they fill: they may
  // not sink through the surface by more than that plus the elastic settlement.
  CHECK(lowest > surface - 0.25 * h);
  // The block starts resting on the obstacle: what gravity releases goes into
  // motion and friction, and the balance closes as on a wall.
  const Energies e = solver.energies();
  const double released = start.gravity - e.gravity;
  std::printf("energy: released by gravity %.4g J/m, kinetic %.4g, friction %.4g, balance error %.2e of it\n",
              released, e.kinetic, e.walls, (e.total() - start.total()) / released);
  CHECK(e.walls == Approx(released * mu / std::tan(theta)).epsilon(0.05));
  // Off a grid line the face acts on nodes inside the obstacle, and the
  // projections there take a little more of the motion.
  CHECK(std::abs(e.total() - start.total()) < (surface == 0.5 ? 2e-3 : 3e-2) * released);
}

TEST_CASE("a block dropped on an obstacle comes to rest on it, no matter its corners", "[mpm][obstacle]") {
  // A narrow rigid pillar under the middle of a falling block: the block must
  // rest on the pillar's top (tipping is symmetric), not pass through it. Grid
  // contact acts through the shape functions: a particle stops once its
  // stencil reaches the face's nodes, so falling material rests within the
  // kernel's reach of the face (1.5 cells for B-splines), never below it.
  const double g = 9.81, h = 0.1;
  const Grid<2> gr = grid(4.0, 4.0, h);
  Settings<2> s;
  s.gravity = {0, -g};
  s.local_damping = 0.5;
  s.walls[2] = {Wall::Type::fixed};
  s.obstacles.push_back({{1.8, 0}, {2.2, 1.0}, {Wall::Type::friction, 0.5}});
  Solver<2> solver(gr, elastic({1000, 2e7, 0.3}), block(gr, {1.5, 1.5}, {2.5, 2.0}, 1000, 2), s);
  while (solver.time() < 1.5) solver.step(solver.stable_time_step());
  double lowest_over_pillar = 1e9, mean_x = 0;
  const auto& p = solver.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::abs(p.x[i].x() - 2.0) < 0.2) lowest_over_pillar = std::min(lowest_over_pillar, p.x[i].y());
    mean_x += p.x[i].x() / static_cast<double>(p.size());
  }
  std::printf("\nblock on a pillar: lowest particle over the pillar %.4f m (top 1.0 m), mean x %.4f m, kinetic "
              "energy %.2e J/m\n",
              lowest_over_pillar, mean_x, solver.energies().kinetic);
  CHECK(lowest_over_pillar > 1.0);
  CHECK(lowest_over_pillar < 1.0 + 1.5 * h);
  CHECK(mean_x == Approx(2.0).margin(0.01));
  CHECK(solver.energies().kinetic < 1e-3 * 1000 * 0.5 * g * 0.5);
}

TEST_CASE("a body overlapping an obstacle is an error naming both", "[mpm][obstacle][scene]") {
  auto doc = scene::Document::parse(R"toml(
[scene]
solvers = ["mpm"]
end_time = "1 s"
[mpm.grid]
size = ["2 m", "2 m"]
cell_size = "0.1 m"
[[mpm.obstacles]]
box_min = ["0 m", "0 m"]
box_max = ["2 m", "0.5 m"]
contact = "friction"
friction_coefficient = 0.3
[[mpm.materials]]
name = "rock"
density = "2500 kg/m3"
youngs_modulus = "1 GPa"
poisson_ratio = 0.25
[[mpm.bodies]]
material = "rock"
box_min = ["0.5 m", "0.4 m"]
box_max = ["1 m", "1 m"]
)toml",
                                    "overlap.toml");
  auto root = doc->root();
  read_scene_header(root);
  CHECK_THROWS_WITH(read_setup<2>(*root.table("mpm", "", true)),
                    Catch::Contains("overlap.toml") && Catch::Contains("mpm.bodies[0].box_min") &&
                        Catch::Contains("overlaps obstacle 1"));
}

TEST_CASE("a settling stage brings a block to rest against its support, and the release lets it go",
          "[mpm][obstacle][stage]") {
  // Gravity pulls sideways (-x) a block standing on a frictionless floor
  // against a roller support. Settling must bring it to rest there; once the
  // support is gone the block must slide freely: x = -g t^2 / 2 from rest.
  const double g = 9.81, h = 0.1;
  const Grid<2> gr = grid(4.0, 1.0, h);
  Settings<2> s;
  s.gravity = {-g, 0};
  s.walls[2] = Wall{Wall::Type::roller};
  s.obstacles.push_back({{1.0, 0.0}, {1.5, 1.0}, {Wall::Type::roller}, true});
  Solver<2> solver(gr, elastic({1000, 5e7, 0.3}), block(gr, {1.5, 0}, {2.5, 0.5}, 1000, 2), s);
  solver.settle({0.3, 0.8}, std::nullopt);
  // Equilibrium: the support carries the block's weight, sigma_xx growing
  // linearly from the free end, -rho g L / 2 on average.
  double mean_sxx = 0;
  const auto count = static_cast<double>(solver.particles().size());
  for (const auto& st : solver.particles().stress) mean_sxx += st(0, 0) / count;
  std::printf("\nsettled: mean sigma_xx %.1f Pa (equilibrium %.1f Pa)\n", mean_sxx, -1000 * g * 1.0 / 2);
  CHECK(mean_sxx == Approx(-1000 * g * 1.0 / 2).epsilon(0.03));
  CHECK(solver.time() == 0.0);
  CHECK(solver.steps() == 0);
  CHECK(solver.energies().kinetic == 0.0);
  double rest = 1e9;
  for (const auto& x : solver.particles().x) rest = std::min(rest, x.x());
  CHECK(rest > 1.5);  // held by the support, within the elastic squeeze
  const auto start = solver.particles().x;
  const double t_end = 0.2;
  while (solver.time() < t_end) solver.step(std::min(solver.stable_time_step(), t_end - solver.time()));
  const auto& p = solver.particles();
  double moved = 0;
  for (std::size_t i = 0; i < p.size(); ++i) moved += (p.x[i].x() - start[i].x()) / static_cast<double>(p.size());
  std::printf("\nafter the release: mean displacement %.5f m (free fall %.5f m)\n", moved, -0.5 * g * t_end * t_end);
  CHECK(moved == Approx(-0.5 * g * t_end * t_end).epsilon(0.02));
}

TEST_CASE("a support without a settling stage is a scene error", "[mpm][obstacle][scene]") {
  auto doc = scene::Document::parse(R"toml(
[scene]
solvers = ["mpm"]
end_time = "1 s"
[mpm.grid]
size = ["2 m", "2 m"]
cell_size = "0.5 m"
[[mpm.obstacles]]
box_min = ["0 m", "0 m"]
box_max = ["0.5 m", "2 m"]
support = true
[[mpm.materials]]
name = "rock"
density = "2000 kg/m3"
youngs_modulus = "1 GPa"
poisson_ratio = 0.25
[[mpm.bodies]]
material = "rock"
box_min = ["0.5 m", "0 m"]
box_max = ["2 m", "1 m"]
)toml",
                                    "support.toml");
  auto root = doc->root();
  read_scene_header(root);
  CHECK_THROWS_WITH(read_setup<2>(*root.table("mpm", "", true)),
                    Catch::Contains("support.toml") && Catch::Contains("obstacles[0].support") &&
                        Catch::Contains("[mpm.settle]"));
}

TEST_CASE("a rigid platen presses two columns side by side to one settlement, loading the stiffer one more",
          "[mpm][platen]") {
  // Columns of E1 = 20 MPa (x < 0.5) and E2 = 10 MPa (x > 0.5), nu = 0, on
  // rollers, under a plate with F = 10 kN/m: the plate sinks by
  // F b / (E1 a1 + E2 a2) and each column carries E_i times the common strain
  // (a traction would load both alike).
  const double force = 1e4, e1 = 2e7, e2 = 1e7, b = 1.0;
  const Grid<2> gr = grid(1.5, 1.5, 0.05);
  Settings<2> s;
  s.viscous_damping = 600;
  // The sudden load rings grid-scale modes whose damping the books overstate
  // by O(omega dt) (30 % of the load's work at Courant 0.3, 0.6 % at 0.05).
  s.courant = 0.05;
  s.walls = {Wall{Wall::Type::roller}, Wall{}, Wall{Wall::Type::roller}, Wall{}};
  s.platens.push_back({Vec<2>(-1, b), Vec<2>(2, 2), 1, -force, std::nullopt});
  auto particles = block(gr, {0, 0}, {1, b}, 1000, 2);
  for (std::size_t i = 0; i < particles.size(); ++i) particles.material[i] = particles.x[i].x() < 0.5 ? 0 : 1;
  std::vector<std::unique_ptr<Material<2>>> materials;
  materials.push_back(std::make_unique<LinearElastic<2>>("stiff", Elasticity{1000, e1, 0}));
  materials.push_back(std::make_unique<LinearElastic<2>>("soft", Elasticity{1000, e2, 0}));
  Solver<2> solver(gr, std::move(materials), std::move(particles), s);
  while (solver.time() < 0.1) solver.step(std::min(solver.stable_time_step(), 0.1 - solver.time()));
  const auto& p = solver.particles();
  double stiff = 0, soft = 0, top = 0;
  int n_stiff = 0, n_soft = 0, n_top = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    // Away from the bond between the columns, where the strains must match.
    if (p.x0[i].x() < 0.3) stiff += p.stress[i](1, 1), ++n_stiff;
    if (p.x0[i].x() > 0.7) soft += p.stress[i](1, 1), ++n_soft;
    if (p.x0[i].y() > b - 0.025) top += p.x0[i].y() - p.x[i].y(), ++n_top;
  }
  stiff /= n_stiff;
  soft /= n_soft;
  top /= n_top;
  const double settlement = force * b / (0.5 * e1 + 0.5 * e2);
  const Energies e = solver.energies();
  std::printf("\nplaten on two columns: settlement %.4e m (plate) %.4e m (top particles), exact %.4e; stress stiff "
              "%.0f Pa, soft %.0f Pa (exact %.0f, %.0f); balance error %.2e of the load's work\n",
              -solver.platen_displacement()[0], top, settlement, stiff, soft, -e1 * settlement / b,
              -e2 * settlement / b, e.total() / e.external);
  // The plate's nodes sit a quarter cell above the top particles.
  CHECK(-solver.platen_displacement()[0] == Approx(settlement).epsilon(0.02));
  CHECK(top == Approx(settlement).epsilon(0.03));
  CHECK(stiff / soft == Approx(e1 / e2).epsilon(0.05));
  CHECK(std::abs(e.total()) < 1e-2 * e.external);
}

// An obstacle's nodes within a ghost row's reach of a fixed or roller wall:
// the ghosts must mirror them as the obstacle leaves them. Mirrored before,
// the ghosts carried velocities no energy book saw (the outburst's seam meets
// its floor rock on the fixed bottom wall: its books were open by 1e-8).
TEST_CASE("material pressed into an obstacle that stands on a wall keeps its energy books closed to roundoff",
          "[mpm][obstacle]") {
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::bspline);
  const Wall::Type floor = GENERATE(Wall::Type::fixed, Wall::Type::roller);
  const Grid<2> gr = grid(2.0, 1.0, 0.1);
  Settings<2> s;
  s.shape = shape;
  s.gravity = {0, -9.81};
  s.walls = {Wall{}, Wall{}, Wall{floor}, Wall{}};
  s.obstacles.push_back({Vec<2>(0, 0), Vec<2>(0.5, 0.4), Wall{Wall::Type::friction, 0.4}, false});
  auto particles = block(gr, {0.5, 0}, {1.2, 0.6}, 1000, 2);
  for (auto& v : particles.v) v = Vec<2>(-3, -1);
  Solver<2> solver(gr, elastic({1000, 1e6, 0.3}), std::move(particles), s);
  EnergyAudit audit;
  for (int k = 0; k < 300; ++k) {
    solver.step(solver.stable_time_step());
    audit.record(solver.energies(), solver.time());
  }
  INFO("books open by " << audit.open_share() << " of the largest term, " << audit.largest_term() << " J/m");
  CHECK(audit.open_share() < 1e-12);
  CHECK(solver.energies().walls > 0);  // the friction worked
}

// Where a fixed or roller wall meets a friction wall, the corner's ghosts
// mirror ghosts beyond the friction wall: their masses are folded there, and
// the energy books take each to move as its mirror. Constrained in turn with
// the mirrors, depth by depth, friction broke that at a fixed wall under the
// shapes that reach past a wall row (B-splines, GIMP), with friction on
// either wall; linear shapes and roller walls hold it either way, and guard
// against its return here.
template <int Dim>
std::size_t unmirrored_in_corner(Scheme scheme, ShapeKind shape, Wall::Type mirrored, bool friction_floor) {
  Grid<Dim> g;
  if constexpr (Dim == 2)
    g = grid(2.0, 2.0, 0.1);
  else
    g = grid(Vec<3>{1.0, 1.0, 1.0}, 0.1);
  // A body thrown into the corner of the left wall, the floor and (3D) the back.
  Particles<Dim> p = block(g, Vec<Dim>::Zero(), Vec<Dim>::Constant(0.5), 1000, 2);
  Vec<Dim> thrown = Vec<Dim>::Constant(-0.5);
  thrown[0] = -2.0;
  thrown[1] = -1.0;
  for (auto& v : p.v) v = thrown;
  Settings<Dim> s;
  s.scheme = scheme;
  s.shape = shape;
  s.gravity[1] = -9.81;
  const Wall friction{Wall::Type::friction, 0.4};
  s.walls[0] = friction_floor ? Wall{mirrored} : friction;
  s.walls[2] = friction_floor ? friction : Wall{mirrored};
  if constexpr (Dim == 3) s.walls[4] = {mirrored};
  Solver<Dim> solver(g, elastic<Dim>({1000, 1e7, 0.3}), std::move(p), s);
  std::size_t unmirrored = 0;
  for (int k = 0; k < 20; ++k) {
    solver.step(solver.stable_time_step());
    unmirrored += solver.unmirrored_ghosts();
  }
  return unmirrored;
}

TEST_CASE("where a friction wall meets a fixed or roller one, every ghost moves as its mirror", "[mpm][friction]") {
  const Scheme scheme = GENERATE(Scheme::usf, Scheme::usl, Scheme::musl);
  const ShapeKind shape = GENERATE(ShapeKind::linear, ShapeKind::gimp, ShapeKind::bspline);
  const Wall::Type mirrored = GENERATE(Wall::Type::fixed, Wall::Type::roller);
  const bool friction_floor = GENERATE(true, false);
  const char* const schemes[] = {"USF", "USL", "MUSL"};
  const char* const shapes[] = {"linear", "GIMP", "B-spline"};
  INFO(schemes[static_cast<int>(scheme)] << ", " << shapes[static_cast<int>(shape)] << ", "
                                         << (mirrored == Wall::Type::fixed ? "fixed" : "roller")
                                         << " wall, friction on the " << (friction_floor ? "floor" : "left wall"));
  CHECK(unmirrored_in_corner<2>(scheme, shape, mirrored, friction_floor) == 0);
  CHECK(unmirrored_in_corner<3>(scheme, shape, mirrored, friction_floor) == 0);
}
