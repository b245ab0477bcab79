#include "mpm_solid/scene_reader.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/limits.hpp"
#include "mpm_solid/scene_parts.hpp"

namespace outburst::mpm {

using scene::Key;
using scene::Range;
using namespace reading;

namespace {

constexpr std::array<const char*, 6> side_names{"left", "right", "bottom", "top", "back", "front"};
constexpr std::array<char, 3> axis_names{'x', 'y', 'z'};

Wall read_wall(const scene::Table& t, std::string_view side, double friction) {
  const auto type = t.choice<Wall::Type>({side, "\"open\" (particles may leave), \"fixed\", \"roller\" (no normal "
                                                "motion) or \"friction\" (Coulomb, unilateral)",
                                          "open"},
                                         {{"open", Wall::Type::open},
                                          {"fixed", Wall::Type::fixed},
                                          {"roller", Wall::Type::roller},
                                          {"friction", Wall::Type::friction}});
  return {type, type == Wall::Type::friction ? friction : 0.0};
}

template <int Dim>
void read_obstacles(const scene::Table& s, Settings<Dim>& st, const Grid<Dim>& grid) {
  for (const auto& o : s.table_array("obstacles", Dim == 2 ? "rigid fixed rectangles inside the grid (roof and floor "
                                                             "rock, supports); faces best on grid lines"
                                                           : "rigid fixed boxes inside the grid (roof and floor rock, "
                                                             "supports); faces best on grid planes")) {
    const auto [lov, hiv] = read_box<Dim>(o, "");
    if ((hiv.array() <= grid.lower.array()).any() || (lov.array() >= grid.upper.array()).any())
      o.fail("box_min", "the obstacle lies outside the grid");
    const auto type = o.choice<Wall::Type>({"contact", "\"friction\" (Coulomb, material may separate), \"roller\" "
                                                       "(bonded normal to the face, free to slide) or \"fixed\" "
                                                       "(bonded)",
                                            "friction"},
                                           {{"fixed", Wall::Type::fixed},
                                            {"roller", Wall::Type::roller},
                                            {"friction", Wall::Type::friction}});
    const double mu = o.number({"friction_coefficient", "Coulomb coefficient of a \"friction\" contact", "0",
                                Range::non_negative()});
    const bool support = o.boolean({"support", "true: holds the material only during [mpm.settle] (the face "
                                               "before excavation); the dynamic stage starts without it",
                                    "false"});
    st.obstacles.push_back({lov, hiv, {type, type == Wall::Type::friction ? mu : 0.0}, support});
  }
}

template <int Dim>
void read_platens(const scene::Table& s, Settings<Dim>& st, const Grid<Dim>& grid) {
  for (const auto& t : s.table_array("platens", "rigid, massless, frictionless loading plates: the grid nodes in "
                                                "the box move together along its axis")) {
    const auto [lov, hiv] = read_box<Dim>(t, "the box of grid nodes the plate holds");
    if ((hiv.array() < grid.lower.array()).any() || (lov.array() > grid.upper.array()).any())
      t.fail("box_min", "the platen lies outside the grid");
    // Grid nodes lie every h from the grid's corner, ghost nodes included.
    for (int d = 0; d < Dim; ++d) {
      const double first = std::max(std::ceil((lov[d] - grid.lower[d]) / grid.h), -1.0 * Grid<Dim>::ghost);
      const double last =
          std::min(std::floor((hiv[d] - grid.lower[d]) / grid.h), 1.0 * grid.cells[d] + Grid<Dim>::ghost);
      if (first > last)
        t.fail("box_min", fmt::format("the platen's box holds no grid node: along {} the nodes lie every {:g} m from "
                                      "{:g} m",
                                      axis_names[d], grid.h, grid.lower[d]));
    }
    const int axis = Dim == 2 ? t.choice<int>({"direction", "the axis the plate moves along: \"x\" or \"y\""},
                                              {{"x", 0}, {"y", 1}})
                              : t.choice<int>({"direction", "the axis the plate moves along: \"x\", \"y\" or \"z\""},
                                              {{"x", 0}, {"y", 1}, {"z", 2}});
    Platen<Dim> platen{lov, hiv, axis, 0, std::nullopt};
    if (t.has("velocity")) {
      if (t.has("force")) t.fail("force", "give the plate a force or a velocity, not both");
      platen.velocity = t.quantity({"velocity", "speed of a displacement-controlled plate along that axis, whatever "
                                                "force it takes (negative: toward smaller coordinates)"},
                                   units::velocity);
    } else if constexpr (Dim == 2) {
      platen.force = t.quantity({"force", "load on the plate along that axis per metre of depth (negative: toward "
                                          "smaller coordinates); or give a velocity"},
                                units::force_per_length);
    } else {
      platen.force = t.quantity({"force", "load on the plate along that axis (negative: toward smaller "
                                          "coordinates); or give a velocity"},
                                units::force);
    }
    st.platens.push_back(platen);
  }
}

// A traction loads the outermost layer of particles facing one way inside a
// box: each carries the traction times its share of the surface (its spacing,
// squared in 3D).
template <int Dim>
void read_tractions(const scene::Table& s, Setup<Dim>& setup) {
  auto& p = setup.particles;
  for (const auto& t : s.table_array("tractions", "constant loads on body surfaces (the crustal stress)")) {
    const auto [lo, hi] = read_box<Dim>(t, "the box holding the loaded surface");
    const std::string facing =
        Dim == 2 ? t.choice({"surface", "which surface of the particles in the box: the one facing \"up\", \"down\", "
                                        "\"left\" or \"right\""},
                            {"up", "down", "left", "right"})
                 : t.choice({"surface", "which surface of the particles in the box: the one facing \"up\", \"down\", "
                                        "\"left\", \"right\", \"back\" (-z) or \"front\" (+z)"},
                            {"up", "down", "left", "right", "back", "front"});
    const Vec<Dim> value = to_vec<Dim>(
        t.quantity_vector({"traction", Dim == 2 ? "force per area [x, y] on that surface (compression pushes into "
                                                  "the body)"
                                                : "force per area [x, y, z] on that surface (compression pushes into "
                                                  "the body)"},
                          units::pressure, Dim));
    const int axis = facing == "up" || facing == "down" ? 1 : facing == "left" || facing == "right" ? 0 : 2;
    const double sign = facing == "up" || facing == "right" || facing == "front" ? 1.0 : -1.0;
    std::vector<std::size_t> inside;
    double extreme = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p.size(); ++i)
      if ((p.x[i].array() >= lo.array()).all() && (p.x[i].array() <= hi.array()).all()) {
        inside.push_back(i);
        extreme = std::max(extreme, sign * p.x[i][axis]);
      }
    if (inside.empty()) t.fail("box_min", "the box holds no particle to load");
    p.need_loads();
    for (std::size_t i : inside) {
      const double spacing = 2 * p.half_width[i] * setup.grid.h;
      const double share = Dim == 2 ? spacing : spacing * spacing;
      if (sign * p.x[i][axis] >= extreme - 0.5 * spacing) p.surface_force[i] += value * share;
    }
  }
}

// The solver's settings of the [mpm] table itself (scheme, shape, transfer,
// time step, damping, gravity).
template <int Dim>
void read_settings(const scene::Table& s, Setup<Dim>& setup) {
  Settings<Dim>& st = setup.settings;
  st.scheme = s.choice<Scheme>({"scheme", "\"usf\" (update stress first, the paper's), \"usl\" or \"musl\"", "usf"},
                               {{"usf", Scheme::usf}, {"usl", Scheme::usl}, {"musl", Scheme::musl}});
  st.shape = s.choice<ShapeKind>(
      {"shape", "grid shape functions: \"linear\", \"gimp\" or \"bspline\" (quadratic)", "bspline"},
      {{"linear", ShapeKind::linear}, {"gimp", ShapeKind::gimp}, {"bspline", ShapeKind::bspline}});
  st.apic = s.choice({"transfer", "velocity transfer: \"flip\" (FLIP/PIC blend) or \"apic\" (affine PIC)", "flip"},
                     {"flip", "apic"}) == "apic";
  if (!st.apic)
    st.flip_fraction = s.number({"flip_fraction", "FLIP/PIC blend: 1 pure FLIP, 0 pure PIC", "0.99",
                                 Range::between(0, 1)});
  st.courant = s.number({"courant", "time step as a fraction of the CFL limit h / (c + |v|)", "0.3",
                         Range{0.0, 1.0, false, true}});
  st.smooth_dilatation = s.choice({"locking_remedy",
                                   "\"nodal_dilatation\": smooth the volumetric strain rate over the nodes "
                                   "(against volumetric locking and pressure checkerboards), or \"none\"",
                                   "none"},
                                  {"nodal_dilatation", "none"}) == "nodal_dilatation";
  st.local_damping = s.number({"local_damping",
                               "Cundall local damping coefficient (quasi-static stages; 0: off)", "0",
                               Range::between(0, 1)});
  st.viscous_damping = s.quantity({"viscous_damping", "mass-proportional damping c, nodal force -c m v (smooth, "
                                                     "for quasi-static solids in iterated couplings; 0: off)",
                                   "0 1/s", Range::non_negative()},
                                  units::rate);
  st.gravity = to_vec<Dim>(s.quantity_vector({"gravity", "gravitational acceleration",
                                              Dim == 2 ? "0 m/s2, 0 m/s2" : "0 m/s2, 0 m/s2, 0 m/s2"},
                                             units::acceleration, Dim));
  if (s.has("time_step"))
    setup.fixed_time_step = s.quantity({"time_step", "fixed step instead of the CFL step (checked against it)",
                                        "", Range::positive()},
                                       units::time);
}

template <int Dim>
Grid<Dim> read_grid(const scene::Table& s) {
  const auto grid = s.table("grid", "the background grid", true);
  const auto origin = grid->quantity_vector(
      {"origin", corner_doc<Dim>(true, ""), Dim == 2 ? "0 m, 0 m" : "0 m, 0 m, 0 m"}, units::length, Dim);
  const auto size = grid->quantity_vector(
      {"size", Dim == 2 ? "width and height (two lengths: plane strain; three: 3D)" : "extent along x, y and z",
       "", Range::positive()},
      units::length, Dim);
  const double h = grid->quantity({"cell_size", Dim == 2 ? "edge of the square cells" : "edge of the cubic cells",
                                   "", Range::positive()},
                                  units::length);
  Grid<Dim> gr;
  gr.h = h;
  gr.lower = to_vec<Dim>(origin);
  std::array<double, Dim> cells;
  double nodes = 1;
  for (int d = 0; d < Dim; ++d) {
    cells[d] = size[d] / h;
    nodes *= cells[d] + 1 + 2 * Grid<Dim>::ghost;
  }
  limits::refuse_memory(*grid, "cell_size", nodes * bytes_per_node<Dim>(),
                        fmt::format("a grid of {:.3g} cells of {:g} m", fmt::join(cells, " x "), h));
  for (int d = 0; d < Dim; ++d) {
    const double n = cells[static_cast<std::size_t>(d)];
    if (n > std::numeric_limits<int>::max() / 2)
      grid->fail("cell_size", fmt::format("{:.3g} cells along one side are more than a grid may have", n));
    gr.cells[d] = static_cast<int>(std::lround(n));
    if (std::abs(n - gr.cells[d]) > 1e-9 * n || gr.cells[d] < 1)
      grid->fail("cell_size", fmt::format("the grid size {:g} m is not a whole number of cells of {:g} m", size[d], h));
  }
  for (int d = 0; d < Dim; ++d) gr.upper[d] = gr.lower[d] + gr.cells[d] * h;
  return gr;
}

template <int Dim>
void read_walls(const scene::Table& s, Settings<Dim>& st) {
  if (const auto walls = s.table("walls", Dim == 2 ? "conditions on the grid's four edges"
                                                   : "conditions on the grid's six faces",
                                 false)) {
    const double mu = walls->number({"friction_coefficient", "Coulomb coefficient of \"friction\" walls", "0",
                                     Range::non_negative()});
    for (int w = 0; w < 2 * Dim; ++w) st.walls[w] = read_wall(*walls, side_names[w], mu);
  }
}

// [mpm.settle]; without it, no obstacle may be a support.
template <int Dim>
void read_settling(const scene::Table& s, Setup<Dim>& setup) {
  const Settings<Dim>& st = setup.settings;
  if (const auto settle = s.table("settle", "a quasi-static stage before t = 0: in-situ stress and gravity brought "
                                            "to equilibrium with local damping and the supports in place", false)) {
    setup.settling.duration = settle->quantity({"time", "length of the stage", "", Range::positive()}, units::time);
    setup.settling.damping =
        settle->number({"damping", "Cundall local damping coefficient during the stage", "0.8",
                        Range::between(0, 1)});
  } else {
    for (std::size_t k = 0; k < st.obstacles.size(); ++k)
      if (st.obstacles[k].support)
        s.fail(fmt::format("obstacles[{}].support", k),
               "a support is removed when [mpm.settle] ends; add that section or drop the key");
  }
}

// The materials, in order; returns their names.
template <int Dim>
std::vector<std::string> read_materials(const scene::Table& s, Setup<Dim>& setup) {
  std::vector<std::string> names;
  for (const auto& m : s.table_array("materials", "constitutive models, referred to by name")) {
    const std::string name = m.string({"name", "material name"});
    if (std::find(names.begin(), names.end(), name) != names.end())
      m.fail("name", fmt::format("material \"{}\" is defined twice", name));
    const MaterialModel& model = m.model("model", "constitutive model", "elastic", material_models());
    Elasticity e{};
    e.density = m.quantity({"density", "mass density", "", Range::positive()}, units::density);
    e.youngs_modulus = m.quantity({"youngs_modulus", "Young's modulus E", "", Range::positive()}, units::pressure);
    e.poisson_ratio = m.number({"poisson_ratio", "Poisson's ratio", "", Range{-1.0, 0.5, false, false}});
    setup.materials.push_back(
        model.template read<Dim>(m, {name, e, setup.grid.h, crack_cells(setup.settings.shape)}));
    names.push_back(name);
  }
  if (names.empty()) s.fail("materials", "give at least one [[mpm.materials]]");
  return names;
}

// The particles nearest the tracer points, by id.
template <int Dim>
void read_tracers(const scene::Table& s, Setup<Dim>& setup) {
  const Grid<Dim>& gr = setup.grid;
  if (s.has("tracers")) {
    for (const auto& point : s.quantity_points({"tracers", Dim == 2 ? "points [[\"x\", \"y\"], ...]: the particle "
                                                                      "nearest each at t = 0 has its history written"
                                                                    : "points [[\"x\", \"y\", \"z\"], ...]: the "
                                                                      "particle nearest each at t = 0 has its history "
                                                                      "written"},
                                               units::length, Dim)) {
      const Vec<Dim> x = to_vec<Dim>(point);
      if (!gr.inside(x))
        s.fail("tracers", fmt::format("the tracer at {} lies outside the grid, which holds {}", point_text<Dim>(x),
                                      extent_text(gr)));
      std::size_t nearest = 0;
      for (std::size_t i = 1; i < setup.particles.size(); ++i)
        if ((setup.particles.x[i] - x).squaredNorm() < (setup.particles.x[nearest] - x).squaredNorm()) nearest = i;
      setup.tracers.push_back(setup.particles.id[nearest]);
    }
  }
}

}  // namespace

int scene_dimension(const scene::Table& s) {
  const auto grid = s.table("grid", "the background grid", true);
  const auto length = grid->array_length("size");
  if (length && *length != 2 && *length != 3)
    grid->fail("size", fmt::format("expected two lengths (width and height: plane strain) or three (x, y and z: "
                                   "3D), got {}",
                                   *length));
  return length == 3u ? 3 : 2;
}

template <int Dim>
Setup<Dim> read_setup(const scene::Table& s) {
  Setup<Dim> setup;
  read_settings(s, setup);
  setup.grid = read_grid<Dim>(s);
  read_walls(s, setup.settings);
  read_obstacles(s, setup.settings, setup.grid);
  read_platens(s, setup.settings, setup.grid);
  read_settling(s, setup);
  const auto names = read_materials(s, setup);
  read_bodies(s, setup, names);
  // The materials' own particle fields (a heterogeneous coal's draws) now, so
  // that the checks on the step see the particles as the solver will.
  const auto members = material_members(setup.particles, setup.materials.size());
  for (std::size_t m = 0; m < members.size(); ++m) setup.materials[m]->create_fields(setup.particles, members[m]);
  read_tractions(s, setup);
  read_tracers(s, setup);
  return setup;
}

template <int Dim>
std::string overhang(const Grid<Dim>& grid, const Vec<Dim>& lo, const Vec<Dim>& hi) {
  const double tolerance = 1e-9 * grid.h;
  std::string text;
  for (int side = 0; side < 2 * Dim; ++side) {
    const int d = side / 2;
    const bool low = side % 2 == 0;
    const double past = low ? grid.lower[d] - lo[d] : hi[d] - grid.upper[d];
    const double edge = low ? grid.lower[d] : grid.upper[d];
    if (past > tolerance)
      text += fmt::format("{}{:g} m past the grid's {} {} ({} = {:g} m)", text.empty() ? "" : " and ", past,
                          side_names[side], Dim == 2 ? "edge" : "face", axis_names[d], edge);
  }
  return text;
}

// Refuses a run whose particles times steps are beyond any real run's.
template <int Dim>
void check_particle_steps(const scene::Table& mpm, const Setup<Dim>& setup, double steps) {
  const double particles = static_cast<double>(setup.particles.size());
  limits::refuse_count(mpm, "bodies", particles * steps, limits::max_particle_steps, "particle-steps",
                       fmt::format("{:.3g} particles over {:.3g} steps; coarsen grid.cell_size or lower "
                                   "particles_per_cell, or shorten the run",
                                   particles, steps));
}

template <int Dim>
void check_time_step(const scene::Table& mpm, const Setup<Dim>& setup) {
  if (!setup.fixed_time_step) return;
  const double limit = stable_time_step(setup.materials, setup.particles, setup.grid.h, 1.0);
  if (*setup.fixed_time_step > limit)
    mpm.fail("time_step", fmt::format("{:.3g} s exceeds the stability limit h / (c + |v|) = {:.3g} s of this scene; "
                                      "use a smaller step or drop the key to let the CFL condition choose",
                                      *setup.fixed_time_step, limit));
}

template <int Dim>
void check_run_length(const scene::Table& mpm, const Setup<Dim>& setup, double end_time) {
  const double span = setup.settling.duration + end_time;
  if (setup.fixed_time_step) {
    limits::refuse_count(mpm, "time_step", span / *setup.fixed_time_step, limits::max_steps, "MPM steps",
                         fmt::format("settling and end_time, {:.3g} s, in steps of {:.3g} s; lengthen time_step", span,
                                     *setup.fixed_time_step));
    check_particle_steps(mpm, setup, span / *setup.fixed_time_step);
    return;
  }
  // The stable step at the start, as the solver computes it.
  const auto& p = setup.particles;
  double fastest = 0;
  std::size_t material = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::size_t m = static_cast<std::size_t>(p.material[i]);
    const double stiffness = p.modulus_scale.empty() ? 1.0 : p.modulus_scale[i];
    const double speed = std::sqrt(stiffness) * setup.materials[m]->elasticity().p_wave_speed() + p.v[i].norm();
    if (speed > fastest) fastest = speed, material = m;
  }
  const double step = setup.settings.courant * setup.grid.h / fastest;
  limits::refuse_count(
      mpm, "courant", span / step, limits::max_steps, "MPM steps",
      fmt::format("settling and end_time, {:.3g} s, in stable steps of courant {:g} x cell {:g} m / {:.3g} m/s, the "
                  "speed of the P wave of material \"{}\" (youngs_modulus, density, a heterogeneity's stiffest draw) and "
                  "its particles; change those "
                  "or shorten the run",
                  span, setup.settings.courant, setup.grid.h, fastest, setup.materials[material]->name()));
  check_particle_steps(mpm, setup, span / step);
}

template Setup<2> read_setup<2>(const scene::Table&);
template Setup<3> read_setup<3>(const scene::Table&);
template std::string overhang(const Grid<2>&, const Vec<2>&, const Vec<2>&);
template std::string overhang(const Grid<3>&, const Vec<3>&, const Vec<3>&);
template void check_run_length(const scene::Table&, const Setup<2>&, double);
template void check_run_length(const scene::Table&, const Setup<3>&, double);
template void check_time_step(const scene::Table&, const Setup<2>&);
template void check_time_step(const scene::Table&, const Setup<3>&);

}  // namespace outburst::mpm
