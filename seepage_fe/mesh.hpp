#pragma once
// Quadrilateral meshes for the seepage solver: generated structured rectangles
// (with optional geometric grading) or unstructured quads read from Gmsh.
//
// Regions (cell sets with their own material) and boundaries (edge sets where
// conditions apply) are named: "left", "right", "bottom", "top" on generated
// meshes, Gmsh physical group names on read ones.

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace outburst::seepage {

struct Mesh {
  struct Boundary {
    std::string name;
    std::vector<std::array<int, 2>> edges;
  };

  std::vector<Eigen::Vector2d> nodes;
  std::vector<std::array<int, 4>> cells;  // counter-clockwise
  std::vector<int> cell_region;           // index into region_names
  std::vector<std::string> region_names;
  std::vector<Boundary> boundaries;

  std::size_t num_nodes() const { return nodes.size(); }
  std::size_t num_cells() const { return cells.size(); }
  std::array<Eigen::Vector2d, 4> corners(std::size_t cell) const {
    const auto& c = cells[cell];
    return {nodes[c[0]], nodes[c[1]], nodes[c[2]], nodes[c[3]]};
  }
  // -1 when absent.
  int region_index(const std::string& name) const;
  const Boundary* boundary(const std::string& name) const;
  std::vector<std::string> boundary_names() const;
};

struct StructuredMeshSpec {
  Eigen::Vector2d origin{0.0, 0.0};
  Eigen::Vector2d size{1.0, 1.0};
  std::array<int, 2> cells{1, 1};
  // Ratio of the last to the first cell size in each direction (1: uniform).
  std::array<double, 2> grading{1.0, 1.0};
  struct Region {
    std::string name;
    bool whole_domain = true;
    Eigen::Vector2d box_min, box_max;
  };
  // A cell belongs to the last region whose box holds its centre.
  std::vector<Region> regions;
};

// Throws std::invalid_argument naming the region when a cell has none.
Mesh make_structured_mesh(const StructuredMeshSpec& spec);

// Gmsh MSH 4.1 ASCII with physical groups: 2D groups become regions (4-node quads
// only), 1D groups boundaries. Coordinates are multiplied by `length_scale` (to m).
// Errors (std::runtime_error) name the file, the line and what was expected.
Mesh read_gmsh(const std::filesystem::path& file, double length_scale = 1.0);

// Checks every cell has positive area and counter-clockwise, convex corners;
// throws std::runtime_error naming the first bad cell.
void check_mesh(const Mesh& mesh, const std::string& source);

}  // namespace outburst::seepage
