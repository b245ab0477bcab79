#include "seepage_fe/scene_reader.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/limits.hpp"

namespace outburst::seepage {

using scene::Key;
using scene::Range;

namespace {

// What the solver holds per node, counted low: the mesh, the sparse Jacobian
// and CHOLMOD's factor (measured: 1.4 kB per node at 1e6 nodes, in 2D; a 3D
// node's row couples 27 nodes instead of 9, and its factor fills in more, so
// the bound is lower still there).
constexpr double bytes_per_node = 1000;

// What [seepage.mesh] describes. A Gmsh mesh is read at once; a generated
// one is returned as its spec so the regions can be painted into it before it
// is generated.
template <int Dim>
using GeneratedSpec = std::conditional_t<Dim == 2, StructuredMeshSpec, BoxMeshSpec>;
using MeshInput = std::variant<Mesh, StructuredMeshSpec, Mesh3, BoxMeshSpec>;

Mesh generate(const StructuredMeshSpec& spec) { return make_structured_mesh(spec); }
Mesh3 generate(const BoxMeshSpec& spec) { return make_box_mesh(spec); }

// A rectangle (Dim = 2) or a box: its corner, size, cells and grading.
template <int Dim>
GeneratedSpec<Dim> read_generated(const scene::Table& t) {
  constexpr bool plane = Dim == 2;
  const auto origin = t.quantity_vector(
      {"origin", plane ? "lower-left corner" : "the corner of least x, y and z", plane ? "0 m, 0 m" : "0 m, 0 m, 0 m"},
      units::length, Dim);
  const auto size = t.quantity_vector(
      {"size", plane ? "width and height" : "lengths along x, y and z", "", Range::positive()}, units::length, Dim);
  const auto cells = t.integer_vector<int>(
      {"cells", plane ? "number of cells along x and y" : "number of cells along x, y and z", "", Range::at_least(1)},
      Dim);
  // Nodes are numbered with int, and must fit in memory.
  double nodes = 1;
  for (const int c : cells) nodes *= c + 1.0;
  if (nodes > std::numeric_limits<int>::max())
    t.fail("cells", fmt::format("{} cells have {:.3g} nodes, more than the {} a mesh may have", fmt::join(cells, " x "),
                                nodes, std::numeric_limits<int>::max()));
  limits::refuse_memory(t, "cells", nodes * bytes_per_node,
                        fmt::format("a mesh of {} cells ({:.3g} nodes)", fmt::join(cells, " x "), nodes));
  const auto grading = t.number_vector(
      {"grading",
       plane ? "ratio of the last to the first cell size along x and y (1: uniform)"
             : "ratio of the last to the first cell size along x, y and z (1: uniform)",
       plane ? "1, 1" : "1, 1, 1", Range::positive()},
      Dim);
  GeneratedSpec<Dim> spec;
  for (int d = 0; d < Dim; ++d) {
    spec.origin[d] = origin[d];
    spec.size[d] = size[d];
    spec.cells[d] = cells[d];
    spec.grading[d] = grading[d];
  }
  return spec;
}

MeshInput read_mesh(const scene::Table& t) {
  const std::string type = t.choice(
      {"type",
       "\"structured\": a generated rectangle; \"box\": a generated box of hexahedra (3D); \"gmsh\": a mesh file, "
       "of quadrangles (plane) or hexahedra (3D)",
       "structured"},
      {"structured", "box", "gmsh"});
  if (type == "gmsh") {
    const auto file = t.file({"file", "Gmsh MSH 4.1 ASCII file, relative to the scene file"});
    const double scale = t.quantity(
        {"length_unit", "length of one coordinate unit in the mesh file", "1 m", Range::positive()},
        units::length);
    std::variant<Mesh, Mesh3> mesh;
    try {
      mesh = read_gmsh_mesh(file, scale);
    } catch (const std::runtime_error& e) {
      t.fail("file", e.what());
    }
    const std::size_t nodes = std::visit([](const auto& m) { return m.num_nodes(); }, mesh);
    limits::refuse_memory(t, "file", static_cast<double>(nodes) * bytes_per_node,
                          fmt::format("a mesh of {} nodes", nodes));
    return std::visit([](auto& m) -> MeshInput { return std::move(m); }, mesh);
  }
  if (type == "box") return read_generated<3>(t);
  return read_generated<2>(t);
}

Material read_material(const scene::Table& r, Law law) {
  Material m{};
  if (law == Law::gas) {
    m.conductivity = r.quantity({"lambda",
                                 "gas permeability coefficient in q = -lambda grad(p^2), e.g. "
                                 "\"0.1 m2/(MPa2 d)\"",
                                 "", Range::positive()},
                                units::gas_conductivity);
    const auto [a, dimension] = r.quantity_of(
        {"gas_content_coefficient",
         "A in X = A sqrt(p): per coal volume (\"2 MPa^-0.5\") or per coal mass "
         "(\"1.25 m3/(t MPa^0.5)\", needs coal_density)",
         "", Range::positive()},
        units::gas_content_per_volume, units::gas_content_per_mass);
    m.capacity = a;
    if (dimension == units::gas_content_per_mass)
      m.capacity *= r.quantity({"coal_density",
                                "coal density, converting a per-mass gas content coefficient",
                                "", Range::positive()},
                               units::density);
  } else {
    const double k = r.quantity({"permeability", "intrinsic permeability", "", Range::positive()},
                                units::area);
    const double mu = r.quantity(
        {"viscosity", "fluid dynamic viscosity", "1e-3 Pa s", Range::positive()}, units::viscosity);
    m.conductivity = k / mu;
    m.capacity = r.quantity({"storage_coefficient",
                             "S in S dp/dt = div((k/mu) grad p): specific storage per pressure",
                             "", Range::positive()},
                            units::inverse_pressure);
  }
  m.initial_pressure = r.quantity(
      {"initial_pressure", "pressure at t = 0",
       "", law == Law::gas ? Range::positive() : Range{}},
      units::pressure);
  return m;
}

// The solver's own settings: time scheme, nonlinear solver and its limits.
void read_settings(const scene::Table& s, Settings& st) {
  st.scheme = s.choice<TimeScheme>({"time_scheme", "\"bdf2\" (second order, L-stable) or \"backward_euler\"", "bdf2"},
                                   {{"bdf2", TimeScheme::bdf2}, {"backward_euler", TimeScheme::backward_euler}});
  st.method = s.choice<NonlinearMethod>(
      {"nonlinear_solver", "\"newton\" (with line search) or \"picard\" (secant storage)", "newton"},
      {{"newton", NonlinearMethod::newton}, {"picard", NonlinearMethod::picard}});
  st.tolerance = s.number({"tolerance", "nonlinear convergence: max |du| / max |u|", "1e-10",
                           Range::positive()});
  st.max_iterations = s.integer<int>(
      {"max_iterations", "nonlinear iterations before the step is cut", "30", Range::between(1, 1000)});
  // Sixty halvings shrink a step 1e18 times: past any step the clock resolves.
  st.max_step_cuts = s.integer<int>(
      {"max_step_cuts", "halvings of a failing step before the run stops", "12", Range::between(0, 60)});
  st.linear_solver = s.choice<LinearSolver>(
      {"linear_solver",
       "the Newton systems: \"direct\" (CHOLMOD, its mode and ordering picked by size), \"cg\" (conjugate "
       "gradients with an incomplete Cholesky preconditioner) or \"lagged\" (conjugate gradients preconditioned "
       "by CHOLMOD's factor of an earlier Jacobian)",
       "direct"},
      {{"direct", LinearSolver::direct}, {"cg", LinearSolver::cg}, {"lagged", LinearSolver::lagged}});
  const bool iterative = st.linear_solver != LinearSolver::direct;
  if (iterative)
    st.cg_tolerance = s.number({"cg_tolerance", "conjugate gradients stop at ||J du + r|| <= cg_tolerance ||r||",
                                "1e-8", Range{0.0, 1.0, false, false}});
  else if (s.has("cg_tolerance"))
    s.fail("cg_tolerance", "applies to conjugate gradients only: set seepage.linear_solver = \"cg\" or \"lagged\"");
  if (iterative)
    st.cg_forcing = s.choice<Forcing>(
        {"cg_forcing",
         "how tightly conjugate gradients solve each Newton system: \"fixed\" (every one to cg_tolerance) or "
         "\"adaptive\" (Eisenstat and Walker's forcing term: from 0.1 of the residual while Newton is far from the "
         "solution down to cg_tolerance as it converges; a step converges on its update only after a solve to "
         "cg_tolerance)",
         "fixed"},
        {{"fixed", Forcing::fixed}, {"adaptive", Forcing::adaptive}});
  else if (s.has("cg_forcing"))
    s.fail("cg_forcing", "applies to conjugate gradients only: set seepage.linear_solver = \"cg\" or \"lagged\"");
  if (st.linear_solver == LinearSolver::cg)
    st.cg_max_iterations = s.integer<int>({"cg_max_iterations",
                                           "conjugate gradient iterations before the step is cut and retried",
                                           "5000", Range::between(1, 1e7)});
  else if (s.has("cg_max_iterations"))
    s.fail("cg_max_iterations", "applies to incomplete-Cholesky conjugate gradients only: set "
                                "seepage.linear_solver = \"cg\"");
  if (st.linear_solver == LinearSolver::lagged)
    st.lag_max_iterations = s.integer<int>(
        {"lag_max_iterations",
         "conjugate gradient iterations allowed on an earlier Jacobian's factor: past half of them the factor "
         "is renewed at the next Newton iteration, past all of them at once (the linear law ignores it: its "
         "Jacobian does not move)",
         "10", Range::between(1, 1000)});
  else if (s.has("lag_max_iterations"))
    s.fail("lag_max_iterations", "applies to the lagged factorisation only: set seepage.linear_solver = \"lagged\"");
}

// The step sizes of a run of its own (a coupled run's window sets them).
void read_time_steps(const scene::Table& s, TimeStepControl& steps, bool own_time_steps) {
  steps.maximum = std::numeric_limits<double>::infinity();
  if (own_time_steps) {
    steps.first = s.quantity({"time_step", "first time step", "", Range::positive()}, units::time);
    steps.growth = s.number({"time_step_growth", "factor between successive steps (1: constant; up to 2)", "1",
                             Range::between(1, 2)});
    if (s.has("max_time_step")) {
      steps.maximum = s.quantity({"max_time_step", "largest step when time_step_growth > 1", "", Range::positive()},
                                 units::time);
      if (steps.maximum < steps.first)
        s.fail("max_time_step",
               fmt::format("{:g} s is below the first step, time_step = {:g} s", steps.maximum, steps.first));
    }
  }
}

// On a generated mesh, boxes paint regions over the rectangle or box, in
// order: a cell takes the last region whose box holds its centre.
template <int Dim>
void read_painted_regions(const std::vector<scene::Table>& regions, const scene::Table& s, GeneratedSpec<Dim>& spec,
                          SetupOf<Dim>& setup) {
  constexpr bool plane = Dim == 2;
  Model& model = setup.model;
  MeshOf<Dim>& mesh = setup.mesh;
  spec.regions.clear();
  for (const auto& r : regions) {
    RegionBoxOf<Dim> region;
    region.name = r.string({"name", "region name (used in output and messages)"});
    region.whole_domain = !r.has("box_min");
    if (!region.whole_domain) {
      const auto lo = r.quantity_vector(
          {"box_min", plane ? "lower-left corner of the region's box" : "corner of least x, y and z of the region's box"},
          units::length, Dim);
      const auto hi = r.quantity_vector({"box_max", plane ? "upper-right corner of the region's box"
                                                          : "corner of greatest x, y and z of the region's box"},
                                        units::length, Dim);
      for (int d = 0; d < Dim; ++d) {
        region.box_min[d] = lo[d];
        region.box_max[d] = hi[d];
      }
    }
    spec.regions.push_back(region);
    model.materials.push_back(read_material(r, model.law));
  }
  try {
    mesh = generate(spec);
  } catch (const std::invalid_argument& e) {
    s.fail("regions", e.what());
  } catch (const std::runtime_error& e) {  // check_mesh: cells graded or sized below round-off
    s.table("mesh", "the finite element mesh", true)
        ->fail("grading", fmt::format("{}: its cells are too thin to compute with; make the grading milder, or the "
                                      "box larger or of fewer cells",
                                      e.what()));
  }
  // A cell takes the last region whose box holds it: a region left with no
  // cell was painted over, which the scene cannot have meant.
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (std::find(mesh.cell_region.begin(), mesh.cell_region.end(), static_cast<int>(r)) == mesh.cell_region.end())
      regions[r].fail(regions[r].has("box_min") ? "box_min" : "name",
                      fmt::format("region \"{}\" holds no cell: {} (a cell belongs to the last region whose box "
                                  "holds its centre)",
                                  spec.regions[r].name,
                                  spec.regions[r].whole_domain ? "a later region covers the whole mesh"
                                                                : "its box holds no cell centre not covered by a "
                                                                  "later region"));
}

// On a Gmsh mesh, each physical surface (3D: volume) must have a region of the
// same name.
template <int Dim>
void read_named_regions(const std::vector<scene::Table>& regions, const scene::Table& s, SetupOf<Dim>& setup) {
  const char* group = Dim == 2 ? "physical surface" : "physical volume";
  Model& model = setup.model;
  const MeshOf<Dim>& mesh = setup.mesh;
  model.materials.resize(mesh.region_names.size());
  std::vector<bool> given(mesh.region_names.size(), false);
  for (const auto& r : regions) {
    const std::string name = r.string(
        {"name", Dim == 2 ? "a physical surface name of the Gmsh mesh" : "a physical volume name of the Gmsh mesh"});
    const int index = mesh.region_index(name);
    if (index < 0)
      r.fail("name",
             fmt::format("the mesh has no {} \"{}\" (it has: {})", group, name, fmt::join(mesh.region_names, ", ")));
    if (given[index]) r.fail("name", fmt::format("region \"{}\" is given twice", name));
    given[index] = true;
    model.materials[index] = read_material(r, model.law);
  }
  for (std::size_t i = 0; i < given.size(); ++i)
    if (!given[i])
      s.fail("regions",
             fmt::format("the mesh's {} \"{}\" has no [[seepage.regions]] entry", group, mesh.region_names[i]));
}

template <int Dim>
void read_boundaries(const scene::Table& s, SetupOf<Dim>& setup) {
  Model& model = setup.model;
  const MeshOf<Dim>& mesh = setup.mesh;
  for (const auto& b : s.table_array("boundaries", "boundary conditions (others: no flow)")) {
    BoundaryCondition bc;
    bc.boundary = b.string({"name", Dim == 2 ? "a boundary of the mesh: left, right, bottom, top on a generated mesh, "
                                               "a physical curve name on a Gmsh mesh"
                                             : "a boundary of the mesh: left, right, bottom, top, back, front on a "
                                               "box, a physical surface name on a Gmsh mesh"});
    if (!mesh.boundary(bc.boundary))
      b.fail("name", fmt::format("the mesh has no boundary \"{}\" (it has: {})", bc.boundary,
                                 fmt::join(mesh.boundary_names(), ", ")));
    for (std::size_t k = 0; k < model.boundary_conditions.size(); ++k)
      if (model.boundary_conditions[k].boundary == bc.boundary)
        b.fail("name", fmt::format("boundary \"{}\" already has a condition (seepage.boundaries[{}]); give each "
                                   "boundary one",
                                   bc.boundary, k));
    bc.type = b.choice<BoundaryCondition::Type>(
        {"type", "\"pressure\" (fixed p) or \"flux\" (prescribed inflow)"},
        {{"pressure", BoundaryCondition::Type::pressure}, {"flux", BoundaryCondition::Type::flux}});
    if (bc.type == BoundaryCondition::Type::pressure)
      bc.value = b.time_function({"value", "boundary pressure p, constant or [[time, p], ...]", "",
                                  model.law == Law::gas ? Range::positive() : Range{}},
                                 units::pressure);
    else
      bc.value = b.time_function({"value",
                                  "inflow per boundary area, positive into the domain "
                                  "(standard gas volume for the gas law)"},
                                 units::velocity);
    model.boundary_conditions.push_back(bc);
  }
}

// The regions and boundaries on a mesh read (named regions) or generated
// (painted ones).
template <int Dim, class MeshOrSpec>
SetupOf<Dim> complete_setup(MeshOrSpec& input, const std::vector<scene::Table>& regions, const scene::Table& s,
                            SetupOf<Dim> setup) {
  if constexpr (std::is_same_v<MeshOrSpec, MeshOf<Dim>>) {
    setup.mesh = std::move(input);
    read_named_regions(regions, s, setup);
  } else {
    read_painted_regions(regions, s, input, setup);
  }
  read_boundaries(s, setup);
  return setup;
}

}  // namespace

std::variant<Setup, Setup3> read_any_setup(const scene::Table& s, bool own_time_steps) {
  // The law, settings and steps come before the mesh tells the dimension: a
  // plane setup holds them, and hands them to a 3D one if the mesh is 3D.
  Setup plane;
  plane.model.law = s.choice<Law>({"law",
                                   "\"gas\": P = p^2 with gas content A sqrt(p) (the paper's); \"linear\": "
                                   "Darcy flow of a slightly compressible fluid, unknown p",
                                   "gas"},
                                  {{"gas", Law::gas}, {"linear", Law::linear}});
  read_settings(s, plane.settings);
  read_time_steps(s, plane.steps, own_time_steps);
  auto input = read_mesh(*s.table("mesh", "the finite element mesh", true));
  const auto regions = s.table_array("regions", "materials and initial pressure per region");
  if (regions.empty())
    s.fail("regions", "give at least one [[seepage.regions]] with its material and initial pressure");
  return std::visit(
      [&](auto& mesh_or_spec) -> std::variant<Setup, Setup3> {
        using Input = std::decay_t<decltype(mesh_or_spec)>;
        if constexpr (std::is_same_v<Input, Mesh> || std::is_same_v<Input, StructuredMeshSpec>)
          return complete_setup<2>(mesh_or_spec, regions, s, std::move(plane));
        else
          return complete_setup<3>(mesh_or_spec, regions, s, Setup3{{}, plane.model, plane.settings, plane.steps});
      },
      input);
}


}  // namespace outburst::seepage

namespace outburst::seepage {

double estimated_steps(const TimeStepControl& steps, double end_time) {
  const double g = steps.growth;
  if (g == 1) return end_time / std::min(steps.first, steps.maximum);
  // Steps grow geometrically until they reach the maximum, then stay there.
  const double growing = std::isfinite(steps.maximum) ? std::ceil(std::log(steps.maximum / steps.first) / std::log(g))
                                                      : std::numeric_limits<double>::infinity();
  const double covered = steps.first * (std::pow(g, growing) - 1) / (g - 1);
  if (!(covered < end_time)) return std::log1p(end_time * (g - 1) / steps.first) / std::log(g);
  return growing + (end_time - covered) / steps.maximum;
}

void check_run_length(const scene::Table& seepage, const TimeStepControl& steps, double end_time,
                      double output_interval) {
  // Each output time may cut one step short.
  const double count = estimated_steps(steps, end_time) + end_time / output_interval;
  limits::refuse_count(seepage, "time_step", count, limits::max_steps, "seepage steps",
                       fmt::format("time_step {:.3g} s growing by {:g} up to max_time_step {:.3g} s until end_time "
                                   "{:.3g} s; lengthen time_step or let it grow",
                                   steps.first, steps.growth, steps.maximum, end_time));
}

}  // namespace outburst::seepage
