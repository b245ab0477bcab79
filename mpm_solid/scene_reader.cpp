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

constexpr std::array<const char*, 6> side_names{"left", "right", "bottom", "top", "back", "front"};
constexpr std::array<char, 3> axis_names{'x', 'y', 'z'};

template <int Dim>
Vec<Dim> to_vec(const std::vector<double>& v) {
  Vec<Dim> x;
  for (int d = 0; d < Dim; ++d) x[d] = v[static_cast<std::size_t>(d)];
  return x;
}

// "(1, 2) m" or "(1, 2, 3) m".
template <int Dim>
std::string point_text(const Vec<Dim>& x) {
  std::vector<std::string> parts;
  for (int d = 0; d < Dim; ++d) parts.push_back(fmt::format("{:g}", x[d]));
  return fmt::format("({}) m", fmt::join(parts, ", "));
}

// "[0, 45] x [0, 9] m".
template <int Dim>
std::string extent_text(const Grid<Dim>& grid) {
  std::vector<std::string> parts;
  for (int d = 0; d < Dim; ++d) parts.push_back(fmt::format("[{:g}, {:g}]", grid.lower[d], grid.upper[d]));
  return fmt::format("{} m", fmt::join(parts, " x "));
}

// The corners' key docs: "lower-left corner ..." in 2D.
template <int Dim>
std::string corner_doc(bool lower, std::string_view of) {
  const char* corner = Dim == 2 ? (lower ? "lower-left corner" : "upper-right corner")
                                : (lower ? "lowest corner (smallest x, y, z)" : "highest corner (largest x, y, z)");
  return of.empty() ? std::string(corner) : fmt::format("{} of {}", corner, of);
}

// The box of box_min and box_max, with its upper corner above its lower one.
template <int Dim>
std::pair<Vec<Dim>, Vec<Dim>> read_box(const scene::Table& t, std::string_view of) {
  const Vec<Dim> lo = to_vec<Dim>(t.quantity_vector({"box_min", corner_doc<Dim>(true, of)}, units::length, Dim));
  const Vec<Dim> hi = to_vec<Dim>(t.quantity_vector({"box_max", corner_doc<Dim>(false, of)}, units::length, Dim));
  if (!(hi.array() > lo.array()).all())
    t.fail("box_max", Dim == 2 ? "must lie above and right of box_min" : "must lie beyond box_min along x, y and z");
  return {lo, hi};
}

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

// What the solver holds per grid node, counted low: mass, momentum, force
// and two velocities, the node's coordinates, and each further thread's copy
// of the scattered mass and vectors.
template <int Dim>
double bytes_per_node() {
  return (Dim == 2 ? 80.0 : 120.0) + (Dim == 2 ? 24.0 : 32.0) * (omp_get_max_threads() - 1);
}

// What a particle holds, counted low (position, velocity, stress, gradients:
// Particles<Dim> without its optional fields).
template <int Dim>
constexpr double bytes_per_particle = Dim == 2 ? 224 : 400;

// Index of the obstacle strictly containing x, if any.
template <int Dim>
std::optional<std::size_t> obstacle_at(const std::vector<Obstacle<Dim>>& obstacles, const Vec<Dim>& x) {
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

// A body's shape, for telling whether another body's particles fall inside it:
// a box, in 2D cut to a polygon, in 3D to a sphere.
template <int Dim>
struct BodyShape {
  Vec<Dim> lo, hi;
  std::vector<Vec<2>> polygon;  // 2D; empty: the box
  std::optional<double> radius;  // 3D: the sphere's about `centre`
  Vec<Dim> centre = Vec<Dim>::Zero();
  bool holds(const Vec<Dim>& x) const {
    if (!((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all())) return false;
    if constexpr (Dim == 2)
      return polygon.empty() || inside_polygon(polygon, x);
    else
      return !radius || (x - centre).squaredNorm() <= *radius * *radius;
  }
};

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

// Nodes of a grid with its ghost layers, for the memory estimates: counted
// in double, unlike Grid::num_nodes, so that a grid too large for any
// machine is refused by its estimate rather than wrapped around.
template <int Dim>
double grid_nodes(const Grid<Dim>& gr) {
  double nodes = 1;
  for (int d = 0; d < Dim; ++d) nodes *= gr.cells[d] + 1.0 + 2 * Grid<Dim>::ghost;
  return nodes;
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

// The body's shape: a box, or a polygon (2D), or a sphere (3D).
template <int Dim>
BodyShape<Dim> read_body_shape(const scene::Table& b) {
  BodyShape<Dim> shape;
  if (b.has("polygon")) {
    if constexpr (Dim == 3) {
      b.fail("polygon", "a polygon is a 2D body; a 3D body is a box (box_min, box_max) or a sphere (centre, radius)");
    } else {
      for (const auto& v :
           b.quantity_points({"polygon", "vertices [[\"x m\", \"y m\"], ...] in order"}, units::length, 2))
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
    }
  } else if (b.has("radius")) {
    if constexpr (Dim == 2) b.fail("radius", "a sphere is a 3D body; a 2D body is a box or a polygon");
    shape.centre = to_vec<Dim>(b.quantity_vector({"centre", "centre of a spherical body"}, units::length, Dim));
    const double radius = b.quantity({"radius", "radius of a spherical body", "", Range::positive()}, units::length);
    shape.radius = radius;
    shape.lo = shape.centre.array() - radius;
    shape.hi = shape.centre.array() + radius;
    // A part of the sphere: an octant or a half beside symmetry walls.
    if (b.has("box_min") || b.has("box_max")) {
      const auto [lo, hi] = read_box<Dim>(b, "the box the sphere is cut to (a part of it beside symmetry walls)");
      shape.lo = shape.lo.cwiseMax(lo);
      shape.hi = shape.hi.cwiseMin(hi);
      if (!(shape.hi.array() > shape.lo.array()).all())
        b.fail("box_min", "the box holds no part of the sphere");
    }
  } else {
    std::tie(shape.lo, shape.hi) = read_box<Dim>(b, "a rectangular body");
  }
  return shape;
}

// The in-situ stress of a body: xx, yy, xy in 2D (its out-of-plane stress that
// of plane strain), xx, yy, zz, yz, xz, xy in 3D.
template <int Dim>
std::pair<Mat<Dim>, double> read_initial_stress(const scene::Table& b, double poisson_ratio) {
  Mat<Dim> stress;
  if constexpr (Dim == 2) {
    const auto s0 = b.quantity_vector({"initial_stress", "in-situ stress xx, yy, xy (tension positive)",
                                       "0 Pa, 0 Pa, 0 Pa"},
                                      units::pressure, 3);
    stress << s0[0], s0[2], s0[2], s0[1];
    return {stress, poisson_ratio * (s0[0] + s0[1])};  // plane strain
  } else {
    const auto s0 = b.quantity_vector({"initial_stress", "in-situ stress xx, yy, zz, yz, xz, xy (tension positive)",
                                       "0 Pa, 0 Pa, 0 Pa, 0 Pa, 0 Pa, 0 Pa"},
                                      units::pressure, 6);
    stress << s0[0], s0[5], s0[4], s0[5], s0[1], s0[3], s0[4], s0[3], s0[2];
    return {stress, 0.0};
  }
}

// The bodies, filled with particles of their materials.
template <int Dim>
void read_bodies(const scene::Table& s, Setup<Dim>& setup, const std::vector<std::string>& names) {
  const Grid<Dim>& gr = setup.grid;
  const Settings<Dim>& st = setup.settings;
  const double h = gr.h, nodes = grid_nodes(gr);
  const auto bodies = s.table_array("bodies", "regions filled with particles");
  if (bodies.empty()) s.fail("bodies", "give at least one [[mpm.bodies]] to fill with particles");
  std::vector<BodyShape<Dim>> shapes;
  double particle_bytes = 0;
  for (const auto& b : bodies) {
    const std::string material = b.string({"material", "name of one of the [[mpm.materials]]"});
    const auto found = std::find(names.begin(), names.end(), material);
    if (found == names.end())
      b.fail("material", fmt::format("no material \"{}\" (defined: {})", material, fmt::join(names, ", ")));
    const int index = static_cast<int>(found - names.begin());
    const int ppc = b.integer<int>({"particles_per_cell", Dim == 2 ? "n for n x n particles per cell"
                                                                   : "n for n x n x n particles per cell",
                                    "2", Range::between(1, 8)});
    BodyShape<Dim> shape = read_body_shape<Dim>(b);
    const char* shape_key = b.has("polygon") ? "polygon" : b.has("radius") && !b.has("box_min") ? "centre" : "box_min";
    if (const auto past = overhang(gr, shape.lo, shape.hi); !past.empty())
      b.fail(overhang(gr, shape.lo, shape.lo).empty() && shape_key == std::string_view("box_min") ? "box_max"
                                                                                                  : shape_key,
             fmt::format("the body reaches {}; the grid holds {}, and particles past it would be dropped", past,
                         extent_text(gr)));
    const double per_cell = Dim == 2 ? ppc * ppc : ppc * ppc * ppc;
    particle_bytes += (shape.hi - shape.lo).prod() / std::pow(h, Dim) * per_cell * bytes_per_particle<Dim>;
    limits::refuse_memory(b, shape_key, particle_bytes + nodes * bytes_per_node<Dim>(),
                          fmt::format("the particles of bodies 0 to {} ({} per cell) and the grid", shapes.size(),
                                      per_cell));
    std::vector<Vec<Dim>> points;
    fill_cells(gr, ppc, shape.lo, shape.hi, [&](const Vec<Dim>& x) { return shape.holds(x); }, points);
    if (points.empty()) b.fail(shape_key, "the body holds no particle positions of the grid");
    for (const auto& x : points)
      for (std::size_t k = 0; k < shapes.size(); ++k)
        if (shapes[k].holds(x))
          b.fail(shape_key, fmt::format("the body overlaps mpm.bodies[{}] at {}: the particles there would be "
                                        "doubled",
                                        k, point_text<Dim>(x)));
    shapes.push_back(std::move(shape));
    for (const auto& x : points)
      if (const auto k = obstacle_at(st.obstacles, x))
        b.fail(shape_key, fmt::format("the body overlaps obstacle {} (mpm.obstacles[{}]) at {}", *k + 1, *k,
                                      point_text<Dim>(x)));
    const Vec<Dim> v0 = to_vec<Dim>(b.quantity_vector(
        {"initial_velocity", "velocity at t = 0", Dim == 2 ? "0 m/s, 0 m/s" : "0 m/s, 0 m/s, 0 m/s"},
        units::velocity, Dim));
    const auto& e = setup.materials[index]->elasticity();
    const auto [stress, stress_zz] = read_initial_stress<Dim>(b, e.poisson_ratio);
    const double side = h / ppc, volume = Dim == 2 ? side * side : side * side * side;
    for (const auto& x : points)
      setup.particles.add(x, v0, e.density * volume, volume, 0.5 / ppc, stress, stress_zz, index);
  }
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
