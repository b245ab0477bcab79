// The seepage solver in three dimensions (issue 21): the hexahedron's
// integrals and the box mesh, the sampler, the manufactured solution's order,
// drainage through a face against the 1D similarity solution, and a box one
// cell deep that must reproduce the plane solver, balance included.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "convergence.hpp"
#include "seepage_fe/q1.hpp"
#include "seepage_fixtures.hpp"
#include "similarity.hpp"

using namespace outburst;
using namespace outburst::testing;

namespace {

// A 3 x 3 x 3 box whose interior nodes are moved off the lattice: its cells
// are not parallelepipeds.
seepage::Mesh3 distorted_box() {
  seepage::BoxMeshSpec spec;
  spec.size = {1.5, 1.0, 1.2};
  spec.cells = {3, 3, 3};
  auto mesh = seepage::make_box_mesh(spec);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> shift(-0.08, 0.08);
  for (auto& x : mesh.nodes)
    if (x.x() > 1e-9 && x.x() < 1.5 - 1e-9 && x.y() > 1e-9 && x.y() < 1 - 1e-9 && x.z() > 1e-9 &&
        x.z() < 1.2 - 1e-9)
      x += Eigen::Vector3d(shift(random), shift(random), shift(random));
  seepage::check_mesh(mesh, "the distorted box");
  return mesh;
}

}  // namespace

TEST_CASE("the 3D cell locator keeps at most one bucket per cell on thin slabs", "[seepage][3d][sampling]") {
  for (const double thickness : {1e-6, 1e-4, 3e-22}) {
    seepage::BoxMeshSpec spec;
    spec.size = {1.0, 1.0, thickness};
    spec.cells = {100, 100, 1};
    const auto mesh = seepage::make_box_mesh(spec);
    const seepage::CellLocatorOf<3> locator(mesh);
    INFO("thickness " << thickness);
    CHECK(locator.buckets() <= mesh.num_cells());
    CHECK(locator.locate(Eigen::Vector3d(0.505, 0.305, 0.5 * thickness)));
  }
}

TEST_CASE("a box of hexahedra: volume, face areas and orientation, and the patch test", "[seepage][3d][mesh]") {
  seepage::BoxMeshSpec spec;
  spec.origin = {1.0, -2.0, 0.5};
  spec.size = {2.0, 1.0, 0.5};
  spec.cells = {4, 3, 2};
  spec.grading = {2.0, 1.0, 0.5};
  const auto mesh = seepage::make_box_mesh(spec);
  CHECK(mesh.num_nodes() == 5 * 4 * 3);
  CHECK(mesh.num_cells() == 24);
  double volume = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) volume += seepage::q1::integrals(mesh.corners(c)).lumped.sum();
  CHECK(volume == Approx(1.0).epsilon(1e-12));
  const Eigen::Vector3d centre = spec.origin + 0.5 * spec.size;
  const std::map<std::string, double> areas{{"left", 0.5}, {"right", 0.5}, {"bottom", 1.0},
                                            {"top", 1.0},  {"back", 2.0},  {"front", 2.0}};
  REQUIRE(mesh.boundary_names().size() == 6);
  for (const auto& [name, expected] : areas) {
    INFO(name);
    const auto* b = mesh.boundary(name);
    REQUIRE(b);
    double area = 0;
    for (const auto& face : b->faces) {
      const auto x = mesh.face_corners_of(face);
      for (double w : seepage::q1::face_lumped(x)) area += w;
      const Eigen::Vector3d mid = 0.25 * (x[0] + x[1] + x[2] + x[3]);
      CHECK((x[1] - x[0]).cross(x[3] - x[0]).dot(mid - centre) > 0);  // counter-clockwise from outside
    }
    CHECK(area == Approx(expected).epsilon(1e-12));
  }

  // A linear field gives no residual at interior nodes of distorted cells:
  // 2x2x2 Gauss points integrate grad N_a det J exactly on any hexahedron.
  const auto d = distorted_box();
  const Eigen::Vector3d a(0.7, -1.3, 2.1);
  std::vector<double> residual(d.num_nodes(), 0.0);
  for (std::size_t c = 0; c < d.num_cells(); ++c) {
    const auto k = seepage::q1::integrals(d.corners(c)).stiffness;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j) residual[d.cells[c][i]] += k(i, j) * (1 + a.dot(d.nodes[d.cells[c][j]]));
  }
  int interior = 0;
  for (int k = 1; k < 3; ++k)
    for (int j = 1; j < 3; ++j)
      for (int i = 1; i < 3; ++i, ++interior) CHECK(std::abs(residual[(k * 4 + j) * 4 + i]) < 1e-13);
  CHECK(interior == 8);
}

TEST_CASE("a box paints regions by box as the rectangle does", "[seepage][3d][mesh]") {
  seepage::BoxMeshSpec spec;
  spec.size = {4.0, 2.0, 3.0};
  spec.cells = {8, 4, 6};
  spec.grading = {2.0, 1.0, 1.0};
  spec.regions = {{"coal", true, {}, {}}, {"softened", false, {0.0, 0.0, 1.0}, {1.0, 2.0, 2.0}}};
  const auto mesh = seepage::make_box_mesh(spec);
  REQUIRE(mesh.region_names == std::vector<std::string>{"coal", "softened"});
  int softened = 0;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const auto& x : mesh.corners(c)) centre += 0.125 * x;
    const bool inside = centre.x() <= 1 && centre.z() >= 1 && centre.z() <= 2;
    CHECK(mesh.cell_region[c] == (inside ? 1 : 0));
    softened += inside;
  }
  CHECK(softened > 0);
  spec.regions = {{"softened", false, {0.0, 0.0, 1.0}, {1.0, 2.0, 2.0}}};
  CHECK_THROWS_WITH(seepage::make_box_mesh(spec), Catch::Contains("the cell centred at (") &&
                                                      Catch::Contains(" m) lies in no region's box"));
}

TEST_CASE("the 3D sampler reads a linear field exactly inside the box and nothing outside it",
          "[seepage][3d][sampling]") {
  const Eigen::Vector3d a(2.0, -3.0, 0.5);
  for (const bool distorted : {false, true}) {
    seepage::BoxMeshSpec spec;
    spec.size = {1.5, 1.0, 1.2};
    spec.cells = {3, 3, 3};
    spec.grading = {3.0, 1.0, 0.4};
    const auto mesh = distorted ? distorted_box() : seepage::make_box_mesh(spec);
    const seepage::SamplerOf<3> sampler(mesh);
    Eigen::VectorXd u(static_cast<Eigen::Index>(mesh.num_nodes()));
    for (std::size_t i = 0; i < mesh.num_nodes(); ++i) u[i] = 1 + a.dot(mesh.nodes[i]);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int hint = -1;
    INFO((distorted ? "distorted" : "graded"));
    for (int k = 0; k < 300; ++k) {
      const Eigen::Vector3d x(1.5 * unit(random), unit(random), 1.2 * unit(random));
      const auto s = sampler.sample(u, x, &hint);
      REQUIRE(s);
      CHECK(s->value == Approx(1 + a.dot(x)).epsilon(1e-12));
      CHECK((s->gradient - a).norm() < 1e-11);
    }
    // Boxes take the parallelepipeds' path, distorted cells Newton's.
    const seepage::CellLocatorOf<3> locator(mesh);
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const auto& corner : mesh.corners(c)) centre += 0.125 * corner;
      int hint = static_cast<int>(c);
      const auto hit = locator.locate(centre, &hint);
      REQUIRE(hit);
      CHECK((hit->inverse_jacobian != nullptr) == !distorted);
    }
    CHECK_FALSE(sampler.sample(u, Eigen::Vector3d(0.5, 0.5, 1.3)));
    CHECK_FALSE(sampler.sample(u, Eigen::Vector3d(-0.01, 0.5, 0.5)));
    CHECK(sampler.cell_of(Eigen::Vector3d(1.6, 0.5, 0.5)) == -1);
  }
}

namespace {

// P = 2 + sin(pi x) sin(pi y) sin(pi z) g(t) on the unit cube, P = 2 on its
// faces: the 2D manufactured solution (seepage_manufactured.hpp) one
// dimension up.
namespace cube {
constexpr double pi = 3.14159265358979323846;
constexpr double A = 2.0, lambda = 0.1;
double g(double t) { return 0.5 * (1 + std::cos(3 * t)); }
double dg(double t) { return -1.5 * std::sin(3 * t); }
double bump(const Eigen::Vector3d& x) { return std::sin(pi * x.x()) * std::sin(pi * x.y()) * std::sin(pi * x.z()); }
double exact(const Eigen::Vector3d& x, double t) { return 2 + bump(x) * g(t); }
double source(const Eigen::Vector3d& x, double t) {
  const double s = bump(x), P = 2 + s * g(t);
  return A * 0.25 * std::pow(P, -0.75) * s * dg(t) + lambda * 3 * pi * pi * s * g(t);
}

// || P_h - P ||_L2 with 3x3x3 Gauss points per cell.
double l2_error(const seepage::Solver3& s, double t) {
  const double gp[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double sum = 0;
  const auto& m = s.mesh();
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const auto x = m.corners(c);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) {
          const auto p = seepage::q1::evaluate(x, Eigen::Vector3d(gp[i], gp[j], gp[k]));
          double uh = 0;
          Eigen::Vector3d at = Eigen::Vector3d::Zero();
          for (int a = 0; a < 8; ++a) {
            uh += p.n[a] * s.unknown()[m.cells[c][a]];
            at += p.n[a] * x[a];
          }
          sum += gw[i] * gw[j] * gw[k] * p.det_j * std::pow(uh - exact(at, t), 2);
        }
  }
  return std::sqrt(sum);
}
}  // namespace cube

}  // namespace

TEST_CASE("with a manufactured gas solution Q1 hexahedra converge at second order", "[seepage][3d][mms]") {
  const double T = 0.1;
  const double face = std::sqrt(2.0);
  std::vector<ConvergenceRow> rows;
  for (int n : {4, 8, 16}) {
    std::vector<seepage::BoundaryCondition> faces;
    for (const char* name : {"left", "right", "bottom", "top", "back", "front"})
      faces.push_back(fixed_pressure(name, face));
    auto s = box_solver(seepage::Law::gas, {1, 1, 1}, {n, n, n}, {cube::lambda, cube::A, face}, faces);
    s.set_source(cube::source);
    std::vector<double> p0;
    for (const auto& x : s.mesh().nodes) p0.push_back(std::sqrt(cube::exact(x, 0.0)));
    s.set_initial_pressure(p0);
    for (int k = 0; k < 20; ++k) s.advance(T / 20);  // BDF2, dt = 5e-3: time error below the spatial
    rows.push_back({1.0 / n, cube::l2_error(s, T)});
  }
  print_convergence("seepage MMS in 3D, space (BDF2, dt = 5e-3)", "h", rows);
  for (double order : observed_orders(rows)) CHECK(order == Approx(2.0).margin(0.15));
}

TEST_CASE("drainage of a box through one face follows the self-similar solution", "[seepage][3d][drainage]") {
  // The plane test's strip (test_seepage_drainage.cpp) as a 10 x 1 x 1 box:
  // the closed faces leave the flow one-dimensional.
  const double ratio = 1.0 / 30;
  const DrainageSimilarity exact(ratio * ratio);
  std::vector<ConvergenceRow> profile, emission;
  for (int cells : {50, 100}) {
    auto s = box_solver(seepage::Law::gas, {10, 1, 1}, {cells, 1, 1}, {1.0, 4.0, 1.0},
                        {fixed_pressure("left", ratio)}, {}, {20.0, 1.0, 1.0});
    drain_to_unit_time(s, cells);
    double worst = 0;
    for (std::size_t i = 0; i < s.mesh().num_nodes(); ++i)
      worst = std::max(worst, std::abs(s.unknown()[i] - exact.f(s.mesh().nodes[i].x())));
    const double emitted_exact = 2 * exact.slope_at_face();  // per unit face area, the face 1 x 1
    profile.push_back({10.0 / cells, worst});
    emission.push_back({10.0 / cells, std::abs(s.balance().total_outflow() - emitted_exact) / emitted_exact});
    CHECK(std::abs(s.balance().error()) < 1e-10 * s.balance().initial_stored);
  }
  print_convergence("3D drainage p_f/p0 = 1/30: max |P_h - P| / P0", "h (mean)", profile);
  print_convergence("3D drainage p_f/p0 = 1/30: emission, relative", "h (mean)", emission);
  CHECK(profile.back().error < 2e-4);
  CHECK(emission.back().error < 3e-3);
  for (double order : observed_orders(profile)) CHECK(order > 1.8);
  for (double order : observed_orders(emission)) CHECK(order > 1.5);
}

TEST_CASE("a box one cell deep with closed ends reproduces the plane solver", "[seepage][3d]") {
  // For fields that do not vary along z the term of a hexahedron's stiffness
  // coupling its two layers vanishes, and what is left, like its lumped
  // storage, is its quadrilateral's times half the depth at either end: the
  // nodal values are the plane solver's, the balance its per-metre figures
  // times the depth.
  const double depth = 0.3;
  const seepage::Material coal{1e-17 / 1.1e-5, 2e-3, 3e6};
  const seepage::BoundaryCondition face{"left", seepage::BoundaryCondition::Type::pressure,
                                        TimeFunction({{0.0, 3e6}, {3600.0, 1e5}})};
  const seepage::BoundaryCondition inflow{"right", seepage::BoundaryCondition::Type::flux, TimeFunction(2e-7)};
  auto plane = rectangle_solver(seepage::Law::gas, {10, 2}, {20, 4}, coal, {face, inflow}, {}, {5.0, 1.0});
  auto box = box_solver(seepage::Law::gas, {10, 2, depth}, {20, 4, 1}, coal, {face, inflow}, {}, {5.0, 1.0, 1.0});
  double dt = 60;
  for (int k = 0; k < 20; ++k, dt *= 1.3) {
    plane.advance(dt);
    box.advance(dt);
  }
  const std::size_t layer = plane.mesh().num_nodes();
  REQUIRE(box.mesh().num_nodes() == 2 * layer);
  double worst = 0;
  for (std::size_t i = 0; i < layer; ++i) {
    REQUIRE((box.mesh().nodes[i].head<2>() - plane.mesh().nodes[i]).norm() < 1e-12);
    for (std::size_t at : {i, i + layer}) worst = std::max(worst, std::abs(box.unknown()[at] - plane.unknown()[i]));
  }
  CHECK(worst < 1e-9 * plane.unknown().lpNorm<Eigen::Infinity>());
  CHECK(box.balance().total_outflow() == Approx(depth * plane.balance().total_outflow()).epsilon(1e-9));
  CHECK(box.balance().stored == Approx(depth * plane.balance().stored).epsilon(1e-12));
  // Closed to Newton's tolerance, and open by the plane solver's amount.
  CHECK(std::abs(box.balance().error()) < 1e-8 * box.balance().initial_stored);
  CHECK(std::abs(box.balance().error() - depth * plane.balance().error()) < 1e-12 * box.balance().initial_stored);
  // The sampler and the cell fluxes agree too.
  const Eigen::Vector2d x(3.3, 0.7);
  const auto p2 = plane.pressure_gradient_at(x);
  const auto p3 = box.pressure_gradient_at(Eigen::Vector3d(x.x(), x.y(), 0.4 * depth));
  REQUIRE((p2 && p3));
  CHECK((p3->head<2>() - *p2).norm() < 1e-8 * p2->norm());
  CHECK(std::abs((*p3)[2]) < 1e-8 * p2->norm());
}

TEST_CASE("CHOLMOD factorises 3D meshes supernodally at every size, plane ones simplicially when small",
          "[seepage][3d][direct]") {
  // As measured (seepage_fe/benchmark/orderings.csv and orderings_3d.csv).
  const seepage::Material m{0.1, 2.0, 3.0};
  auto box = box_solver(seepage::Law::gas, {1, 1, 1}, {4, 4, 4}, m, {fixed_pressure("left", 1.0)});
  auto plane = rectangle_solver(seepage::Law::gas, {1, 1}, {4, 4}, m, {fixed_pressure("left", 1.0)});
  CHECK(box.factorisation().name() == "supernodal/nesdis");
  CHECK(plane.factorisation().name() == "simplicial/amd");
}

TEST_CASE("a batch of points in 3D sampled over SIMD lanes gives each point its own sample, bit for bit",
          "[seepage][3d][sampling]") {
  // A graded box and the same sheared (parallelepipeds with full inverse
  // Jacobians), which the lanes take, and a distorted one, which they leave
  // to the one-point search.
  seepage::BoxMeshSpec spec;
  spec.size = {1.5, 1.0, 1.2};
  spec.cells = {3, 3, 3};
  spec.grading = {3.0, 1.0, 0.4};
  const Eigen::Vector3d lower(-0.2, -0.1, -0.1);
  check_batch_samples(seepage::make_box_mesh(spec), lower, Eigen::Vector3d(1.7, 1.1, 1.3), true);
  auto sheared = seepage::make_box_mesh(spec);
  for (auto& x : sheared.nodes) {
    x.x() += 0.3 * x.y() + 0.2 * x.z();
    x.y() += 0.1 * x.z();
  }
  check_batch_samples(sheared, lower, Eigen::Vector3d(2.2, 1.3, 1.3), true);
  check_batch_samples(distorted_box(), lower, Eigen::Vector3d(1.7, 1.1, 1.3), false);
}
