// The linear Darcy law against classical solutions, and two layers in series.
#include <catch2/catch.hpp>

#include <cmath>

#include "convergence.hpp"
#include "seepage_fe/mesh.hpp"
#include "seepage_fixtures.hpp"

using namespace outburst;
using namespace outburst::testing;

TEST_CASE("the linear law matches the erfc solution of a sudden pressure drop",
          "[seepage][linear]") {
  // S dp/dt = (k/mu) p_xx, p(0, t) = 0, p(x, 0) = p0: p = p0 erf(x / (2 sqrt(c t))), c = k/(mu S).
  const double mobility = 1e-12, storage = 1e-9, p0 = 1e6;
  const double c = mobility / storage;  // 1e-3 m^2/s
  const double T = 1000;                // front at about 2 sqrt(c T) = 2 m of a 10 m strip
  std::vector<ConvergenceRow> rows;
  for (int cells : {25, 50, 100, 200}) {
    auto s = rectangle_solver(seepage::Law::linear, {10, 1}, {cells, 1}, {mobility, storage, p0},
                              {fixed_pressure("left", 0.0)});
    run_steps(s, T, 4 * cells);
    double error = 0;
    for (std::size_t i = 0; i < s.mesh().num_nodes(); ++i) {
      const double x = s.mesh().nodes[i].x();
      error = std::max(error, std::abs(s.unknown()[i] - p0 * std::erf(x / (2 * std::sqrt(c * T)))));
    }
    rows.push_back({10.0 / cells, error / p0});
  }
  print_convergence("linear law vs erfc: max |p_h - p| / p0 (BDF2, dt ~ h)", "h", rows);
  CHECK(rows.back().error < 1e-3);
  CHECK(observed_orders(rows).back() == Approx(2.0).margin(0.25));
}

TEST_CASE("two layers in steady flow carry the series flux", "[seepage][linear]") {
  // Left layer 4 m with conductivity k1, right layer 6 m with k2: the steady flux
  // is (u_in - u_out) / (L1/k1 + L2/k2) for either law (u = p or u = p^2).
  for (auto law : {seepage::Law::linear, seepage::Law::gas}) {
    const bool gas = law == seepage::Law::gas;
    const double k1 = 3e-12, k2 = 1e-12, p_in = 2e6, p_out = 1e6;
    seepage::StructuredMeshSpec spec;
    spec.size = {10, 1};
    spec.cells = {20, 2};
    spec.regions = {{"soft", true, {}, {}}, {"hard", false, {4, -1}, {11, 2}}};
    seepage::Model model;
    model.law = law;
    const double capacity = gas ? 1e-3 : 1e-9;
    model.materials = {{k1, capacity, p_out}, {k2, capacity, p_out}};
    model.boundary_conditions = {fixed_pressure("left", p_in), fixed_pressure("right", p_out)};
    seepage::Settings settings;
    settings.scheme = seepage::TimeScheme::backward_euler;
    seepage::Solver s(seepage::make_structured_mesh(spec), model, settings);
    for (int i = 0; i < 40; ++i) s.advance(1e7 * std::pow(1.5, i));  // to steady state
    const double du = seepage::unknown_from_pressure(law, p_in) - seepage::unknown_from_pressure(law, p_out);
    const double exact = du / (4 / k1 + 6 / k2);
    for (const auto& q : s.cell_flux()) {
      CHECK(q.x() == Approx(exact).epsilon(1e-9));
      CHECK(std::abs(q.y()) < 1e-9 * exact);
    }
    std::printf("\ntwo layers (%s law): flux %.12e, series formula %.12e\n", gas ? "gas" : "linear",
                s.cell_flux().front().x(), exact);
  }
}

TEST_CASE("the same problem on the Gmsh mesh and a generated mesh agrees", "[seepage][gmsh]") {
  // Transient drainage of two gas-filled layers through the inlet face, on the
  // unstructured quad mesh of cases/verification/two_layers.msh and on a
  // generated mesh of the same rectangle: both approximate one solution, so
  // the difference shrinks like the discretisation error of the coarser mesh.
  const auto gmsh_mesh = seepage::read_gmsh(std::string(OUTBURST_SOURCE_DIR) + "/cases/verification/two_layers.msh");
  const double p0 = 3e6, pf = 1e5;
  const seepage::Material soft{1e-17, 2e-3, p0}, hard{2e-18, 2e-3, p0};
  seepage::Model model;
  model.law = seepage::Law::gas;
  model.materials.resize(2);
  model.materials[gmsh_mesh.region_index("soft")] = soft;
  model.materials[gmsh_mesh.region_index("hard")] = hard;
  model.boundary_conditions = {fixed_pressure("inlet", pf)};
  seepage::Solver on_gmsh(gmsh_mesh, model, {});

  seepage::StructuredMeshSpec spec;
  spec.size = {10, 1};
  spec.cells = {160, 16};
  spec.regions = {{"soft", true, {}, {}}, {"hard", false, {4, -1}, {11, 2}}};
  seepage::Model model_generated = model;
  model_generated.materials = {soft, hard};
  model_generated.boundary_conditions = {fixed_pressure("left", pf)};
  seepage::Solver on_grid(seepage::make_structured_mesh(spec), model_generated, {});

  const double day = 86400;
  for (int i = 0; i < 40; ++i) {
    on_gmsh.advance(0.5 * day);
    on_grid.advance(0.5 * day);
  }
  double worst = 0;
  for (double x : {0.1, 0.5, 1.0, 2.0, 3.0, 3.9, 4.1, 6.0, 9.0})
    for (double y : {0.1, 0.5, 0.9}) {
      const double a = *on_gmsh.pressure_at({x, y}), b = *on_grid.pressure_at({x, y});
      worst = std::max(worst, std::abs(a - b) / p0);
    }
  const double released_gmsh = on_gmsh.balance().total_outflow();
  const double released_grid = on_grid.balance().total_outflow();
  std::printf("\nGmsh vs generated mesh after 20 d: max |p difference| / p0 = %.2e, released %.6g vs %.6g m3/m\n",
              worst, released_gmsh, released_grid);
  CHECK(worst < 5e-3);
  CHECK(released_gmsh == Approx(released_grid).epsilon(5e-3));
}
