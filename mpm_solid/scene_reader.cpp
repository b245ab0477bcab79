#include "mpm_solid/scene_reader.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace outburst::mpm {

using scene::Key;
using scene::Range;

namespace {

Wall::Type wall_type(const std::string& type) {
  if (type == "fixed") return Wall::Type::fixed;
  if (type == "roller") return Wall::Type::roller;
  if (type == "friction") return Wall::Type::friction;
  return Wall::Type::open;
}

Wall read_wall(const scene::Table& t, std::string_view side, double friction) {
  const std::string type = t.choice({side, "\"open\" (particles may leave), \"fixed\", \"roller\" (no normal "
                                           "motion) or \"friction\" (Coulomb, unilateral)",
                                     "open"},
                                    {"open", "fixed", "roller", "friction"});
  return {wall_type(type), type == "friction" ? friction : 0.0};
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
    const std::string type = o.choice({"contact", "\"friction\" (Coulomb, material may separate), \"roller\" "
                                                  "(bonded normal to the face, free to slide) or \"fixed\" (bonded)",
                                       "friction"},
                                      {"fixed", "roller", "friction"});
    const double mu = o.number({"friction_coefficient", "Coulomb coefficient of a \"friction\" contact", "0",
                                Range::non_negative()});
    const bool support = o.boolean({"support", "true: holds the material only during [mpm.settle] (the face "
                                               "before excavation); the dynamic stage starts without it",
                                    "false"});
    st.obstacles.push_back({lov, hiv, {wall_type(type), type == "friction" ? mu : 0.0}, support});
  }
}

void read_platens(const scene::Table& s, Settings& st, const Grid<2>& grid) {
  for (const auto& t : s.table_array("platens", "rigid, massless, frictionless loading plates: the grid nodes in "
                                                "the box move together along the force")) {
    const auto lo = t.quantity_vector({"box_min", "lower-left corner of the box of grid nodes the plate holds"},
                                      units::length, 2);
    const auto hi = t.quantity_vector({"box_max", "upper-right corner of that box"}, units::length, 2);
    const Vec<2> lov(lo[0], lo[1]), hiv(hi[0], hi[1]);
    if (!(hiv.array() > lov.array()).all()) t.fail("box_max", "must lie above and right of box_min");
    if ((hiv.array() < grid.lower.array()).any() || (lov.array() > grid.upper.array()).any())
      t.fail("box_min", "the platen lies outside the grid");
    const std::string direction =
        t.choice({"direction", "the axis the plate moves along: \"x\" or \"y\""}, {"x", "y"});
    const double force = t.quantity({"force", "load on the plate along that axis per metre of depth (negative: "
                                              "toward smaller coordinates)"},
                                    units::force_per_length);
    st.platens.push_back({lov, hiv, direction == "x" ? 0 : 1, force});
  }
}

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

}  // namespace

Setup read_setup(const scene::Table& s) {
  Setup setup;
  Settings& st = setup.settings;
  const std::string scheme = s.choice(
      {"scheme", "\"usf\" (update stress first, the paper's), \"usl\" or \"musl\"", "usf"}, {"usf", "usl", "musl"});
  st.scheme = scheme == "usf" ? Scheme::usf : scheme == "usl" ? Scheme::usl : Scheme::musl;
  const std::string shape =
      s.choice({"shape", "grid shape functions: \"linear\", \"gimp\" or \"bspline\" (quadratic)", "bspline"},
               {"linear", "gimp", "bspline"});
  st.shape = shape == "linear" ? ShapeKind::linear : shape == "gimp" ? ShapeKind::gimp : ShapeKind::bspline;
  st.apic = s.choice({"transfer", "velocity transfer: \"flip\" (FLIP/PIC blend) or \"apic\" (affine PIC)", "flip"},
                     {"flip", "apic"}) == "apic";
  if (!st.apic)
    st.flip_fraction = s.number({"flip_fraction", "FLIP/PIC blend: 1 pure FLIP, 0 pure PIC", "0.99",
                                 Range::between(0, 1)});
  st.courant = s.number({"courant", "time step as a fraction of the CFL limit h / (c + |v|)", "0.3",
                         Range::between(0, 1)});
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

  const auto grid = s.table("grid", "the background grid", true);
  const auto origin = grid->quantity_vector({"origin", "lower-left corner", "0 m, 0 m"}, units::length, 2);
  const auto size = grid->quantity_vector({"size", "width and height", "", Range::positive()}, units::length, 2);
  const double h = grid->quantity({"cell_size", "edge of the square cells", "", Range::positive()}, units::length);
  Grid<2>& gr = setup.grid;
  gr.h = h;
  gr.lower = {origin[0], origin[1]};
  for (int d = 0; d < 2; ++d) {
    const double n = size[d] / h;
    gr.cells[d] = static_cast<int>(std::lround(n));
    if (std::abs(n - gr.cells[d]) > 1e-9 * n || gr.cells[d] < 1)
      grid->fail("cell_size", fmt::format("the grid size {:g} m is not a whole number of cells of {:g} m", size[d], h));
  }
  gr.upper = gr.lower + Vec<2>(gr.cells[0] * h, gr.cells[1] * h);

  if (const auto walls = s.table("walls", "conditions on the grid's four edges", false)) {
    const double mu = walls->number({"friction_coefficient", "Coulomb coefficient of \"friction\" walls", "0",
                                     Range::non_negative()});
    const char* sides[4] = {"left", "right", "bottom", "top"};
    for (int w = 0; w < 4; ++w) st.walls[w] = read_wall(*walls, sides[w], mu);
  }

  read_obstacles(s, st, gr);
  read_platens(s, st, gr);
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

  std::vector<std::string> names;
  for (const auto& m : s.table_array("materials", "constitutive models, referred to by name")) {
    const std::string name = m.string({"name", "material name"});
    if (std::find(names.begin(), names.end(), name) != names.end())
      m.fail("name", fmt::format("material \"{}\" is defined twice", name));
    const std::string model = m.choice(
        {"model", "\"elastic\" (Jaumann rate), \"drucker_prager\" (perfectly plastic) or \"elastic_damage\" "
                  "(brittle, leaving granular fragments)",
         "elastic"},
        {"elastic", "drucker_prager", "elastic_damage"});
    Elasticity e{};
    e.density = m.quantity({"density", "mass density", "", Range::positive()}, units::density);
    e.youngs_modulus = m.quantity({"youngs_modulus", "Young's modulus E", "", Range::positive()}, units::pressure);
    e.poisson_ratio = m.number({"poisson_ratio", "Poisson's ratio", "", Range{-1.0, 0.5, false, false}});
    if (model == "elastic") {
      setup.materials.push_back(std::make_unique<LinearElastic>(name, e));
    } else if (model == "elastic_damage") {
      DamageParameters d{};
      d.cohesion = m.quantity({"cohesion", "Mohr-Coulomb cohesion c of the intact coal", "", Range::positive()},
                              units::pressure);
      d.friction_angle = m.quantity({"friction_angle", "Mohr-Coulomb friction angle (also of the fragments)", "",
                                     Range{0.0, 1.5, true, false}},
                                    units::angle);
      d.tensile_strength = m.quantity({"tensile_strength", "tensile strength f_t", "", Range::positive()},
                                      units::pressure);
      d.residual_ratio = m.number({"residual_ratio", "residual strength / strength, in tension and compression "
                                                     "(the paper gives none; 0.1 is common for RFPA models)",
                                   "0.1", Range{0.0, 1.0, true, false}});
      d.ultimate_ratio = m.number({"ultimate_strain_ratio", "eta = ultimate tensile strain / strain at f_t, beyond "
                                                            "which D = 1 (the paper gives none; 5-10 is common)",
                                   "5", Range::at_least(1)});
      d.bulking_factor = m.number({"bulking_factor", "largest volume of fully damaged coal over its volume at t = 0: "
                                                     "broken coal bulks to a loose heap, its fragments then part "
                                                     "(1.3-1.6 is typical of broken coal)",
                                   "1.5", Range::at_least(1)});
      setup.materials.push_back(std::make_unique<ElasticDamage>(name, e, d));
    } else {
      const double c = m.quantity({"cohesion", "Mohr-Coulomb cohesion c", "", Range::non_negative()}, units::pressure);
      const double phi = m.quantity({"friction_angle", "Mohr-Coulomb friction angle", "",
                                     Range{0.0, 1.5, true, false}},
                                    units::angle);
      const double psi = m.quantity({"dilation_angle", "dilation angle of the plastic potential (0: no volume "
                                                       "change in plastic flow)",
                                     "0 deg", Range::non_negative()},
                                    units::angle);
      if (psi > phi) m.fail("dilation_angle", "must not exceed the friction angle");
      const std::string fit = m.choice({"fit", "Drucker-Prager cone fitted to Mohr-Coulomb: \"outer\" "
                                               "(compression corners, the paper's), \"inner\" or \"plane_strain\"",
                                        "outer"},
                                       {"outer", "inner", "plane_strain"});
      const auto kind = fit == "outer"   ? DruckerPragerFit::Kind::outer
                        : fit == "inner" ? DruckerPragerFit::Kind::inner
                                         : DruckerPragerFit::Kind::plane_strain;
      setup.materials.push_back(std::make_unique<DruckerPrager>(name, e, c, phi, psi, kind));
    }
    names.push_back(name);
  }
  if (names.empty()) s.fail("materials", "give at least one [[mpm.materials]]");

  const auto bodies = s.table_array("bodies", "regions filled with particles");
  if (bodies.empty()) s.fail("bodies", "give at least one [[mpm.bodies]] to fill with particles");
  for (const auto& b : bodies) {
    const std::string material = b.string({"material", "name of one of the [[mpm.materials]]"});
    const auto found = std::find(names.begin(), names.end(), material);
    if (found == names.end())
      b.fail("material", fmt::format("no material \"{}\" (defined: {})", material, fmt::join(names, ", ")));
    const int index = static_cast<int>(found - names.begin());
    const int ppc = b.integer<int>({"particles_per_cell", "n for n x n particles per cell", "2",
                                    Range::between(1, 8)});
    std::vector<Vec<2>> points;
    if (b.has("polygon")) {
      std::vector<Vec<2>> polygon;
      for (const auto& v : b.quantity_points({"polygon", "vertices [[\"x m\", \"y m\"], ...] in order"},
                                             units::length))
        polygon.emplace_back(v[0], v[1]);
      if (polygon.size() < 3) b.fail("polygon", "a polygon needs at least 3 vertices");
      Vec<2> lo = polygon[0], hi = polygon[0];
      for (const auto& v : polygon) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
      }
      fill_cells(gr, ppc, lo, hi, [&](const Vec<2>& x) { return inside_polygon(polygon, x); }, points);
    } else {
      const auto lo = b.quantity_vector({"box_min", "lower-left corner of a rectangular body"}, units::length, 2);
      const auto hi = b.quantity_vector({"box_max", "upper-right corner of a rectangular body"}, units::length, 2);
      const Vec<2> lov(lo[0], lo[1]), hiv(hi[0], hi[1]);
      if (!((hiv.array() > lov.array()).all())) b.fail("box_max", "must lie above and right of box_min");
      fill_cells(gr, ppc, lov, hiv, [](const Vec<2>&) { return true; }, points);
    }
    const char* shape_key = b.has("polygon") ? "polygon" : "box_min";
    if (points.empty()) b.fail(shape_key, "the body holds no particle positions of the grid");
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
  read_tractions(s, setup);

  if (s.has("tracers")) {
    for (const auto& point : s.quantity_points({"tracers", "points [[\"x\", \"y\"], ...]: the particle nearest "
                                                           "each at t = 0 has its history written"},
                                               units::length)) {
      const Vec<2> x(point[0], point[1]);
      std::size_t nearest = 0;
      for (std::size_t i = 1; i < setup.particles.size(); ++i)
        if ((setup.particles.x[i] - x).squaredNorm() < (setup.particles.x[nearest] - x).squaredNorm()) nearest = i;
      setup.tracers.push_back(setup.particles.id[nearest]);
    }
  }
  return setup;
}

}  // namespace outburst::mpm
