#pragma once
// What the files reading the [mpm] section share (scene_reader.cpp,
// scene_bodies.cpp): vectors and boxes from keys, their text in messages,
// and the memory a grid and its particles will take, counted low.

#include <omp.h>

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "mpm_solid/scene_reader.hpp"

namespace outburst::mpm::reading {

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

// Nodes of a grid with its ghost layers, for the memory estimates: counted
// in double, unlike Grid::num_nodes, so that a grid too large for any
// machine is refused by its estimate rather than wrapped around.
template <int Dim>
double grid_nodes(const Grid<Dim>& gr) {
  double nodes = 1;
  for (int d = 0; d < Dim; ++d) nodes *= gr.cells[d] + 1.0 + 2 * Grid<Dim>::ghost;
  return nodes;
}

// The bodies of [[mpm.bodies]], filled with particles of the materials
// `names` (setup.materials, in order).
template <int Dim>
void read_bodies(const scene::Table& s, Setup<Dim>& setup, const std::vector<std::string>& names);

}  // namespace outburst::mpm::reading
