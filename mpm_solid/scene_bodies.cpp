// Reads [[mpm.bodies]]: each body's shape (a box, a polygon in 2D, a sphere
// in 3D), its material, particles per cell, initial velocity and stress,
// filled with particles on the grid's regular positions.
#include <algorithm>
#include <cmath>
#include <tuple>

#include "common/limits.hpp"
#include "mpm_solid/scene_parts.hpp"

namespace outburst::mpm::reading {

using scene::Range;

namespace {

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

}  // namespace

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

template void read_bodies(const scene::Table&, Setup<2>&, const std::vector<std::string>&);
template void read_bodies(const scene::Table&, Setup<3>&, const std::vector<std::string>&);

}  // namespace outburst::mpm::reading
