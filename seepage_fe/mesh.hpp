#pragma once
// Meshes for the seepage solver: generated rectangles and boxes (with optional
// geometric grading), or unstructured quadrilaterals and hexahedra read from
// Gmsh.
//
// Regions (cell sets with their own material) and boundaries (sets of faces,
// edges in 2D, where conditions apply) are named: "left", "right", "bottom",
// "top" (and "back", "front" on boxes) on generated meshes, Gmsh physical
// group names on read ones.

#include <array>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

namespace outburst::seepage {

// Q1 meshes in Dim = 2 (quadrilaterals) or 3 (hexahedra) dimensions. A
// boundary is a set of faces: edges in 2D, quadrilaterals in 3D.
template <int Dim>
struct MeshOf {
  static_assert(Dim == 2 || Dim == 3);
  static constexpr int dim = Dim;
  static constexpr int cell_corners = 1 << Dim;
  static constexpr int face_corners = 1 << (Dim - 1);
  using Point = Eigen::Matrix<double, Dim, 1>;
  using Cell = std::array<int, cell_corners>;
  using Face = std::array<int, face_corners>;

  struct Boundary {
    std::string name;
    std::vector<Face> faces;
  };

  std::vector<Point> nodes;
  // Quadrilaterals counter-clockwise; hexahedra in Gmsh's order (q1::hex_corner).
  std::vector<Cell> cells;
  std::vector<int> cell_region;           // index into region_names
  std::vector<std::string> region_names;
  std::vector<Boundary> boundaries;

  std::size_t num_nodes() const { return nodes.size(); }
  std::size_t num_cells() const { return cells.size(); }
  std::array<Point, cell_corners> corners(std::size_t cell) const {
    std::array<Point, cell_corners> x;
    for (int a = 0; a < cell_corners; ++a) x[a] = nodes[cells[cell][a]];
    return x;
  }
  std::array<Point, face_corners> face_corners_of(const Face& face) const {
    std::array<Point, face_corners> x;
    for (int a = 0; a < face_corners; ++a) x[a] = nodes[face[a]];
    return x;
  }
  // -1 when absent.
  int region_index(const std::string& name) const;
  const Boundary* boundary(const std::string& name) const;
  std::vector<std::string> boundary_names() const;
};

using Mesh = MeshOf<2>;
using Mesh3 = MeshOf<3>;

// A region of a generated mesh: the whole mesh, or the cells whose centres
// lie in a box (its corners of least and greatest coordinates).
template <int Dim>
struct RegionBoxOf {
  std::string name;
  bool whole_domain = true;
  Eigen::Matrix<double, Dim, 1> box_min, box_max;
};

struct StructuredMeshSpec {
  Eigen::Vector2d origin{0.0, 0.0};
  Eigen::Vector2d size{1.0, 1.0};
  std::array<int, 2> cells{1, 1};
  // Ratio of the last to the first cell size in each direction (1: uniform).
  std::array<double, 2> grading{1.0, 1.0};
  using Region = RegionBoxOf<2>;
  // A cell belongs to the last region whose box holds its centre.
  std::vector<Region> regions;
};

// Throws std::invalid_argument naming the region when a cell has none.
Mesh make_structured_mesh(const StructuredMeshSpec& spec);

// A box of hexahedra, uniform or graded along each axis; its boundaries are
// "left" and "right" (x), "bottom" and "top" (y), "back" and "front" (z), each
// face's corners counter-clockwise seen from outside. Regions as on the
// rectangle, by default one, "domain".
struct BoxMeshSpec {
  Eigen::Vector3d origin{0.0, 0.0, 0.0};
  Eigen::Vector3d size{1.0, 1.0, 1.0};
  std::array<int, 3> cells{1, 1, 1};
  std::array<double, 3> grading{1.0, 1.0, 1.0};  // last over first cell size
  using Region = RegionBoxOf<3>;
  std::vector<Region> regions{{"domain", true, {}, {}}};
};
// Throws std::invalid_argument for a size or cell count below one, and, as
// make_structured_mesh, for a cell in no region.
Mesh3 make_box_mesh(const BoxMeshSpec& spec);

// Gmsh MSH 4.1 ASCII with physical groups, plane or volume as the file holds.
// A mesh with hexahedra (8-node, element type 5) is a volume mesh: physical
// volumes become regions and physical surfaces (4-node quadrangles)
// boundaries, each face turned to face out of its hexahedron. Otherwise it is
// plane: physical surfaces (4-node quadrangles only) become regions and
// physical curves (2-node lines) boundaries. Coordinates are multiplied by
// `length_scale` (to m). Errors (std::runtime_error) name the file, the line
// and what was expected.
std::variant<Mesh, Mesh3> read_gmsh_mesh(const std::filesystem::path& file, double length_scale = 1.0);
// The same, for a mesh that must be plane, or must be a volume mesh.
Mesh read_gmsh(const std::filesystem::path& file, double length_scale = 1.0);
Mesh3 read_gmsh3(const std::filesystem::path& file, double length_scale = 1.0);

// Checks every cell has positive area and counter-clockwise, convex corners
// (a hexahedron: a positive Jacobian at each corner); throws
// std::runtime_error naming the first bad cell.
void check_mesh(const Mesh& mesh, const std::string& source);
void check_mesh(const Mesh3& mesh, const std::string& source);

}  // namespace outburst::seepage
