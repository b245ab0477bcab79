#include "mpm_solid/scene_reader.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/limits.hpp"

namespace outburst::mpm {

using scene::Key;
using scene::Range;

namespace {

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

void read_obstacles(const scene::Table& s, Settings& st, const Grid<2>& grid) {
  for (const auto& o : s.table_array("obstacles", "rigid fixed rectangles inside the grid (roof and floor rock, "
                                                  "supports); faces best on grid lines")) {
    const auto lo = o.quantity_vector({"box_min", "lower-left corner"}, units::length, 2);
    const auto hi = o.quantity_vector({"box_max", "upper-right corner"}, units::length, 2);
    const Vec<2> lov(lo[0], lo[1]), hiv(hi[0], hi[1]);
    if (!(hiv.array() > lov.array()).all()) o.fail("box_max", "must lie above and right of box_min");
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

void read_platens(const scene::Table& s, Settings& st, const Grid<2>& grid) {
  for (const auto& t : s.table_array("platens", "rigid, massless, frictionless loading plates: the grid nodes in "
                                                "the box move together along its axis")) {
    const auto lo = t.quantity_vector({"box_min", "lower-left corner of the box of grid nodes the plate holds"},
                                      units::length, 2);
    const auto hi = t.quantity_vector({"box_max", "upper-right corner of that box"}, units::length, 2);
    const Vec<2> lov(lo[0], lo[1]), hiv(hi[0], hi[1]);
    if (!(hiv.array() > lov.array()).all()) t.fail("box_max", "must lie above and right of box_min");
    if ((hiv.array() < grid.lower.array()).any() || (lov.array() > grid.upper.array()).any())
      t.fail("box_min", "the platen lies outside the grid");
    // Grid nodes lie every h from the grid's corner, ghost nodes included.
    for (int d = 0; d < 2; ++d) {
      const double first = std::max(std::ceil((lov[d] - grid.lower[d]) / grid.h), -1.0 * Grid<2>::ghost);
      const double last = std::min(std::floor((hiv[d] - grid.lower[d]) / grid.h), 1.0 * grid.cells[d] + Grid<2>::ghost);
      if (first > last)
        t.fail("box_min", fmt::format("the platen's box holds no grid node: along {} the nodes lie every {:g} m from "
                                      "{:g} m",
                                      d == 0 ? 'x' : 'y', grid.h, grid.lower[d]));
    }
    const int axis =
        t.choice<int>({"direction", "the axis the plate moves along: \"x\" or \"y\""}, {{"x", 0}, {"y", 1}});
    Platen platen{lov, hiv, axis, 0, std::nullopt};
    if (t.has("velocity")) {
      if (t.has("force")) t.fail("force", "give the plate a force or a velocity, not both");
      platen.velocity = t.quantity({"velocity", "speed of a displacement-controlled plate along that axis, whatever "
                                                "force it takes (negative: toward smaller coordinates)"},
                                   units::velocity);
    } else {
      platen.force = t.quantity({"force", "load on the plate along that axis per metre of depth (negative: toward "
                                          "smaller coordinates); or give a velocity"},
                                units::force_per_length);
    }
    st.platens.push_back(platen);
  }
}

// What the solver holds per grid node, counted low: mass, momentum, force
// and two velocities, the node's coordinates, and each further thread's copy
// of the scattered mass and vectors.
double bytes_per_node() {
  return 80.0 + 24.0 * (omp_get_max_threads() - 1);
}

// What a particle holds, counted low (position, velocity, stress, gradients:
// Particles<2> without its optional fields).
constexpr double bytes_per_particle = 224;

// Index of the obstacle strictly containing x, if any.
std::optional<std::size_t> obstacle_at(const std::vector<Obstacle>& obstacles, const Vec<2>& x) {
  for (std::size_t k = 0; k < obstacles.size(); ++k)
    if ((x.array() > obstacles[k].lower.array()).all() && (x.array() < obstacles[k].upper.array()).all()) return k;
  return std::nullopt;
}

// Even-odd rule point-in-polygon test.
bool inside_polygon(const std::vector<Vec<2>>& poly, const Vec<2>& x) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec<2>& a = poly[i];
    const Vec<2>& b = poly[j];
    if ((a.y() > x.y()) != (b.y() > x.y()) &&
        x.x() < (b.x() - a.x()) * (x.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

// Two edges of a polygon that cross or touch, other than neighbours meeting at
// their shared vertex.
std::optional<std::pair<std::size_t, std::size_t>> crossing_edges(const std::vector<Vec<2>>& poly) {
  const auto orientation = [](const Vec<2>& a, const Vec<2>& b, const Vec<2>& c) {
    const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    return (cross > 0) - (cross < 0);
  };
  const auto on_segment = [](const Vec<2>& a, const Vec<2>& b, const Vec<2>& c) {
    return (c.array() >= a.cwiseMin(b).array()).all() && (c.array() <= a.cwiseMax(b).array()).all();
  };
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      if (j == i + 1 || (i == 0 && j == n - 1)) continue;
      const Vec<2>&a = poly[i], &b = poly[(i + 1) % n], &c = poly[j], &d = poly[(j + 1) % n];
      const int o1 = orientation(a, b, c), o2 = orientation(a, b, d), o3 = orientation(c, d, a),
                o4 = orientation(c, d, b);
      if ((o1 != o2 && o3 != o4) || (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
          (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b)))
        return std::pair{i, j};
    }
  return std::nullopt;
}

// A body's shape, for telling whether another body's particles fall inside it.
struct BodyShape {
  Vec<2> lo, hi;
  std::vector<Vec<2>> polygon;  // empty: the box
  bool holds(const Vec<2>& x) const {
    return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all() &&
           (polygon.empty() || inside_polygon(polygon, x));
  }
};

// A traction loads the outermost layer of particles facing one way inside a
// box: each carries the traction times its share of the surface (its spacing).
void read_tractions(const scene::Table& s, Setup& setup) {
  auto& p = setup.particles;
  for (const auto& t : s.table_array("tractions", "constant loads on body surfaces (the crustal stress)")) {
    const auto lo = t.quantity_vector({"box_min", "lower-left corner of the box holding the loaded surface"},
                                      units::length, 2);
    const auto hi = t.quantity_vector({"box_max", "upper-right corner of that box"}, units::length, 2);
    const std::string facing = t.choice({"surface", "which surface of the particles in the box: the one facing "
                                                    "\"up\", \"down\", \"left\" or \"right\""},
                                        {"up", "down", "left", "right"});
    const auto value = t.quantity_vector({"traction", "force per area [x, y] on that surface (compression "
                                                      "pushes into the body)"},
                                         units::pressure, 2);
    const int axis = facing == "up" || facing == "down" ? 1 : 0;
    const double sign = facing == "up" || facing == "right" ? 1.0 : -1.0;
    std::vector<std::size_t> inside;
    double extreme = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.x[i].x() >= lo[0] && p.x[i].x() <= hi[0] && p.x[i].y() >= lo[1] && p.x[i].y() <= hi[1]) {
        inside.push_back(i);
        extreme = std::max(extreme, sign * p.x[i][axis]);
      }
    if (inside.empty()) t.fail("box_min", "the box holds no particle to load");
    p.need_loads();
    for (std::size_t i : inside) {
      const double spacing = 2 * p.half_width[i] * setup.grid.h;
      if (sign * p.x[i][axis] >= extreme - 0.5 * spacing) p.surface_force[i] += Vec<2>(value[0], value[1]) * spacing;
    }
  }
}

// The solver's settings of the [mpm] table itself (scheme, shape, transfer,
// time step, damping, gravity).
void read_settings(const scene::Table& s, Setup& setup) {
  Settings& st = setup.settings;
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
  const auto g = s.quantity_vector({"gravity", "gravitational acceleration", "0 m/s2, 0 m/s2"},
                                   units::acceleration, 2);
  st.gravity = {g[0], g[1]};
  if (s.has("time_step"))
    setup.fixed_time_step = s.quantity({"time_step", "fixed step instead of the CFL step (checked against it)",
                                        "", Range::positive()},
                                       units::time);

}

Grid<2> read_grid(const scene::Table& s) {
  const auto grid = s.table("grid", "the background grid", true);
  const auto origin = grid->quantity_vector({"origin", "lower-left corner", "0 m, 0 m"}, units::length, 2);
  const auto size = grid->quantity_vector({"size", "width and height", "", Range::positive()}, units::length, 2);
  const double h = grid->quantity({"cell_size", "edge of the square cells", "", Range::positive()}, units::length);
  Grid<2> gr;
  gr.h = h;
  gr.lower = {origin[0], origin[1]};
  const std::array<double, 2> cells{size[0] / h, size[1] / h};
  const double nodes = (cells[0] + 1 + 2 * Grid<2>::ghost) * (cells[1] + 1 + 2 * Grid<2>::ghost);
  limits::refuse_memory(*grid, "cell_size", nodes * bytes_per_node(),
                        fmt::format("a grid of {:.3g} x {:.3g} cells of {:g} m", cells[0], cells[1], h));
  for (int d = 0; d < 2; ++d) {
    const double n = cells[static_cast<std::size_t>(d)];
    if (n > std::numeric_limits<int>::max() / 2)
      grid->fail("cell_size", fmt::format("{:.3g} cells along one side are more than a grid may have", n));
    gr.cells[d] = static_cast<int>(std::lround(n));
    if (std::abs(n - gr.cells[d]) > 1e-9 * n || gr.cells[d] < 1)
      grid->fail("cell_size", fmt::format("the grid size {:g} m is not a whole number of cells of {:g} m", size[d], h));
  }
  gr.upper = gr.lower + Vec<2>(gr.cells[0] * h, gr.cells[1] * h);

  return gr;
}

// Nodes of a grid with its ghost layers, for the memory estimates.
double grid_nodes(const Grid<2>& gr) {
  return (gr.cells[0] + 1.0 + 2 * Grid<2>::ghost) * (gr.cells[1] + 1.0 + 2 * Grid<2>::ghost);
}

void read_walls(const scene::Table& s, Settings& st) {
  if (const auto walls = s.table("walls", "conditions on the grid's four edges", false)) {
    const double mu = walls->number({"friction_coefficient", "Coulomb coefficient of \"friction\" walls", "0",
                                     Range::non_negative()});
    const char* sides[4] = {"left", "right", "bottom", "top"};
    for (int w = 0; w < 4; ++w) st.walls[w] = read_wall(*walls, sides[w], mu);
  }

}

// [mpm.settle]; without it, no obstacle may be a support.
void read_settling(const scene::Table& s, Setup& setup) {
  const Settings& st = setup.settings;
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
std::vector<std::string> read_materials(const scene::Table& s, Setup& setup) {
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
    setup.materials.push_back(model.read(m, {name, e, setup.grid.h, crack_cells(setup.settings.shape)}));
    names.push_back(name);
  }
  if (names.empty()) s.fail("materials", "give at least one [[mpm.materials]]");

  return names;
}

// The bodies, filled with particles of their materials.
void read_bodies(const scene::Table& s, Setup& setup, const std::vector<std::string>& names) {
  const Grid<2>& gr = setup.grid;
  const Settings& st = setup.settings;
  const double h = gr.h, nodes = grid_nodes(gr);
  const auto bodies = s.table_array("bodies", "regions filled with particles");
  if (bodies.empty()) s.fail("bodies", "give at least one [[mpm.bodies]] to fill with particles");
  std::vector<BodyShape> shapes;
  double particle_bytes = 0;
  for (const auto& b : bodies) {
    const std::string material = b.string({"material", "name of one of the [[mpm.materials]]"});
    const auto found = std::find(names.begin(), names.end(), material);
    if (found == names.end())
      b.fail("material", fmt::format("no material \"{}\" (defined: {})", material, fmt::join(names, ", ")));
    const int index = static_cast<int>(found - names.begin());
    const int ppc = b.integer<int>({"particles_per_cell", "n for n x n particles per cell", "2",
                                                Range::between(1, 8)});
    BodyShape shape;
    if (b.has("polygon")) {
      for (const auto& v : b.quantity_points({"polygon", "vertices [[\"x m\", \"y m\"], ...] in order"},
                                             units::length))
        shape.polygon.emplace_back(v[0], v[1]);
      if (shape.polygon.size() < 3) b.fail("polygon", "a polygon needs at least 3 vertices");
      if (const auto crossing = crossing_edges(shape.polygon))
        b.fail("polygon", fmt::format("the polygon crosses itself: its edge from vertex {} meets its edge from "
                                      "vertex {} (vertices count from 0)",
                                      crossing->first, crossing->second));
      shape.lo = shape.hi = shape.polygon[0];
      for (const auto& v : shape.polygon) {
        shape.lo = shape.lo.cwiseMin(v);
        shape.hi = shape.hi.cwiseMax(v);
      }
    } else {
      const auto lo = b.quantity_vector({"box_min", "lower-left corner of a rectangular body"}, units::length, 2);
      const auto hi = b.quantity_vector({"box_max", "upper-right corner of a rectangular body"}, units::length, 2);
      shape.lo = {lo[0], lo[1]};
      shape.hi = {hi[0], hi[1]};
      if (!((shape.hi.array() > shape.lo.array()).all())) b.fail("box_max", "must lie above and right of box_min");
    }
    const char* shape_key = b.has("polygon") ? "polygon" : "box_min";
    if (const auto past = overhang(gr, shape.lo, shape.hi); !past.empty())
      b.fail(overhang(gr, shape.lo, shape.lo).empty() && !b.has("polygon") ? "box_max" : shape_key,
             fmt::format("the body reaches {}; the grid holds [{:g}, {:g}] x [{:g}, {:g}] m, and particles past it "
                         "would be dropped",
                         past, gr.lower.x(), gr.upper.x(), gr.lower.y(), gr.upper.y()));
    particle_bytes += (shape.hi - shape.lo).prod() / (h * h) * ppc * ppc * bytes_per_particle;
    limits::refuse_memory(b, shape_key, particle_bytes + nodes * bytes_per_node(),
                          fmt::format("the particles of bodies 0 to {} ({} per cell) and the grid",
                                      shapes.size(), ppc * ppc));
    std::vector<Vec<2>> points;
    fill_cells(gr, ppc, shape.lo, shape.hi, [&](const Vec<2>& x) { return shape.holds(x); }, points);
    if (points.empty()) b.fail(shape_key, "the body holds no particle positions of the grid");
    for (const auto& x : points)
      for (std::size_t k = 0; k < shapes.size(); ++k)
        if (shapes[k].holds(x))
          b.fail(shape_key, fmt::format("the body overlaps mpm.bodies[{}] at ({:g}, {:g}) m: the particles there "
                                        "would be doubled",
                                        k, x.x(), x.y()));
    shapes.push_back(std::move(shape));
    for (const auto& x : points)
      if (const auto k = obstacle_at(st.obstacles, x))
        b.fail(shape_key, fmt::format("the body overlaps obstacle {} (mpm.obstacles[{}]) at ({:g}, {:g}) m", *k + 1,
                                      *k, x.x(), x.y()));
    const auto v0 = b.quantity_vector({"initial_velocity", "velocity at t = 0", "0 m/s, 0 m/s"}, units::velocity, 2);
    const auto s0 = b.quantity_vector({"initial_stress", "in-situ stress xx, yy, xy (tension positive)",
                                       "0 Pa, 0 Pa, 0 Pa"},
                                      units::pressure, 3);
    const auto& e = setup.materials[index]->elasticity();
    Mat<2> stress;
    stress << s0[0], s0[2], s0[2], s0[1];
    const double stress_zz = e.poisson_ratio * (s0[0] + s0[1]);  // plane strain
    const double volume = (h / ppc) * (h / ppc);
    for (const auto& x : points)
      setup.particles.add(x, Vec<2>(v0[0], v0[1]), e.density * volume, volume, 0.5 / ppc, stress, stress_zz,
                          index);
  }
}

// The particles nearest the tracer points, by id.
void read_tracers(const scene::Table& s, Setup& setup) {
  const Grid<2>& gr = setup.grid;
  if (s.has("tracers")) {
    for (const auto& point : s.quantity_points({"tracers", "points [[\"x\", \"y\"], ...]: the particle nearest "
                                                           "each at t = 0 has its history written"},
                                               units::length)) {
      const Vec<2> x(point[0], point[1]);
      if (!gr.inside(x))
        s.fail("tracers", fmt::format("the tracer at ({:g}, {:g}) m lies outside the grid, which holds [{:g}, {:g}] x "
                                      "[{:g}, {:g}] m",
                                      x.x(), x.y(), gr.lower.x(), gr.upper.x(), gr.lower.y(), gr.upper.y()));
      std::size_t nearest = 0;
      for (std::size_t i = 1; i < setup.particles.size(); ++i)
        if ((setup.particles.x[i] - x).squaredNorm() < (setup.particles.x[nearest] - x).squaredNorm()) nearest = i;
      setup.tracers.push_back(setup.particles.id[nearest]);
    }
  }
}

}  // namespace

Setup read_setup(const scene::Table& s) {
  Setup setup;
  read_settings(s, setup);
  setup.grid = read_grid(s);
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

}  // namespace outburst::mpm

namespace outburst::mpm {

std::string overhang(const Grid<2>& grid, const Vec<2>& lo, const Vec<2>& hi) {
  const double tolerance = 1e-9 * grid.h;
  const std::array<std::tuple<double, const char*, char, double>, 4> sides{{
      {grid.lower.x() - lo.x(), "left", 'x', grid.lower.x()},
      {hi.x() - grid.upper.x(), "right", 'x', grid.upper.x()},
      {grid.lower.y() - lo.y(), "bottom", 'y', grid.lower.y()},
      {hi.y() - grid.upper.y(), "top", 'y', grid.upper.y()},
  }};
  std::string text;
  for (const auto& [past, side, axis, edge] : sides)
    if (past > tolerance)
      text += fmt::format("{}{:g} m past the grid's {} edge ({} = {:g} m)", text.empty() ? "" : " and ", past, side,
                          axis, edge);
  return text;
}

// Refuses a run whose particles times steps are beyond any real run's.
void check_particle_steps(const scene::Table& mpm, const Setup& setup, double steps) {
  const double particles = static_cast<double>(setup.particles.size());
  limits::refuse_count(mpm, "bodies", particles * steps, limits::max_particle_steps, "particle-steps",
                       fmt::format("{:.3g} particles over {:.3g} steps; coarsen grid.cell_size or lower "
                                   "particles_per_cell, or shorten the run",
                                   particles, steps));
}

void check_time_step(const scene::Table& mpm, const Setup& setup) {
  if (!setup.fixed_time_step) return;
  const double limit = stable_time_step(setup.materials, setup.particles, setup.grid.h, 1.0);
  if (*setup.fixed_time_step > limit)
    mpm.fail("time_step", fmt::format("{:.3g} s exceeds the stability limit h / (c + |v|) = {:.3g} s of this scene; "
                                      "use a smaller step or drop the key to let the CFL condition choose",
                                      *setup.fixed_time_step, limit));
}

void check_run_length(const scene::Table& mpm, const Setup& setup, double end_time) {
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

}  // namespace outburst::mpm
