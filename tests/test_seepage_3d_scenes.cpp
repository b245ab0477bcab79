// Gmsh volume meshes (issue 21): the reader's hexahedra, regions and
// boundaries; broken volume meshes refused with the line and what was
// expected.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "seepage_fe/mesh.hpp"
#include "seepage_fe/q1.hpp"

using namespace outburst;
namespace fs = std::filesystem;

namespace {

const fs::path source_dir = OUTBURST_SOURCE_DIR;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("outburst_test_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

fs::path write_file(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

double volume_of(const seepage::Mesh3& m, int region = -1) {
  double v = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    if (region < 0 || m.cell_region[c] == region) v += seepage::q1::integrals(m.corners(c)).lumped.sum();
  return v;
}

}  // namespace

TEST_CASE("the Gmsh reader keeps hexahedra, their regions, and boundary faces turned outward", "[seepage][3d][mesh]") {
  const auto m = seepage::read_gmsh3(source_dir / "cases/drainage_3d/block.msh");
  CHECK(m.num_cells() == 8 * 4 * 6);
  CHECK(m.num_nodes() == 9 * 5 * 7);
  const int softened = m.region_index("softened"), coal = m.region_index("coal");
  REQUIRE((softened >= 0 && coal >= 0 && m.region_names.size() == 2));
  const double total = volume_of(m), soft = volume_of(m, softened), intact = volume_of(m, coal);
  CHECK(total == Approx(24.0).epsilon(1e-12));
  CHECK(soft == Approx(6.0).epsilon(1e-12));
  CHECK(intact == Approx(18.0).epsilon(1e-12));
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const auto& x : m.corners(c)) centre += 0.125 * x;
    CHECK(m.cell_region[c] == (centre.x() < 1 ? softened : coal));
  }

  // Each face's normal (the cross product of its diagonals, in corner order)
  // is its side's outward one; areas by the solver's own face quadrature.
  const std::map<std::string, std::pair<Eigen::Vector3d, double>> sides{
      {"face", {-Eigen::Vector3d::UnitX(), 6.0}}, {"far_end", {Eigen::Vector3d::UnitX(), 6.0}},
      {"floor", {-Eigen::Vector3d::UnitY(), 12.0}}, {"roof", {Eigen::Vector3d::UnitY(), 12.0}},
      {"back", {-Eigen::Vector3d::UnitZ(), 8.0}},  {"front", {Eigen::Vector3d::UnitZ(), 8.0}}};
  REQUIRE(m.boundary_names().size() == sides.size());
  std::printf("\nGmsh block (cases/drainage_3d/block.msh): %zu hexahedra, volume %.15g m3 (softened %.15g, coal "
              "%.15g)\n",
              m.num_cells(), total, soft, intact);
  for (const auto& [name, side] : sides) {
    INFO(name);
    const auto* b = m.boundary(name);
    REQUIRE(b);
    double area = 0, least_alignment = 1;
    for (const auto& face : b->faces) {
      const auto x = m.face_corners_of(face);
      for (double w : seepage::q1::face_lumped(x)) area += w;
      const Eigen::Vector3d normal = (x[2] - x[0]).cross(x[3] - x[1]).normalized();
      least_alignment = std::min(least_alignment, normal.dot(side.first));
    }
    std::printf("  %-8s %3zu faces, area %.15g m2, least normal . outward %.15g\n", name.c_str(), b->faces.size(),
                area, least_alignment);
    CHECK(area == Approx(side.second).epsilon(1e-12));
    CHECK(least_alignment > 1 - 1e-12);
  }
}

TEST_CASE("broken hexahedral meshes are refused with the line and what was expected", "[seepage][3d][mesh]") {
  // One unit cube, "coal", with its face x = 0 the boundary "face".
  const std::string header =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
      "$PhysicalNames\n2\n2 2 \"face\"\n3 1 \"coal\"\n$EndPhysicalNames\n";
  const std::string entities = "$Entities\n0 0 1 1\n1 0 0 0 0 1 1 1 2 0\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n";
  const auto nodes = [](const std::string& top_z) {
    return "$Nodes\n1 8 1 8\n3 1 0 8\n1\n2\n3\n4\n5\n6\n7\n8\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 " + top_z + "\n1 0 " +
           top_z + "\n1 1 " + top_z + "\n0 1 " + top_z + "\n$EndNodes\n";
  };
  const auto elements = [](const std::string& face, const std::string& cells, long face_type = 3,
                           long cell_type = 5) {
    const int n = static_cast<int>(std::count(cells.begin(), cells.end(), '\n'));
    return "$Elements\n2 " + std::to_string(n + 1) + " 1 " + std::to_string(n + 1) + "\n2 1 " +
           std::to_string(face_type) + " 1\n" + face + "\n3 1 " + std::to_string(cell_type) + " " +
           std::to_string(n) + "\n" + cells + "$EndElements\n";
  };
  const std::string cube = "2 1 2 3 4 5 6 7 8\n";
  const fs::path dir = fresh_dir("hexahedra");

  // The good file first, so that each row below tests only what it breaks;
  // its face given inward comes out turned outward.
  for (const std::string face : {"1 1 4 8 5", "1 1 5 8 4"}) {
    const auto m = seepage::read_gmsh3(write_file(dir / "good.msh", header + entities + nodes("1") +
                                                                        elements(face, cube)));
    REQUIRE(m.num_cells() == 1);
    CHECK(volume_of(m) == Approx(1.0).epsilon(1e-14));
    const auto x = m.face_corners_of(m.boundary("face")->faces.at(0));
    CHECK((x[2] - x[0]).cross(x[3] - x[1]).normalized().dot(-Eigen::Vector3d::UnitX()) > 1 - 1e-14);
  }
  // The cube's corners listed mirrored (xi and eta exchanged): read
  // right-handed.
  const auto mirrored = seepage::read_gmsh3(
      write_file(dir / "mirrored.msh", header + entities + nodes("1") + elements("1 1 4 8 5", "2 1 4 3 2 5 8 7 6\n")));
  CHECK(volume_of(mirrored) == Approx(1.0).epsilon(1e-14));
  CHECK(seepage::q1::evaluate(mirrored.corners(0), Eigen::Vector3d::Zero()).det_j > 0);

  struct Row {
    std::string name, text, message;
  };
  const std::string entities_without_volume_group =
      "$Entities\n0 0 1 1\n1 0 0 0 0 1 1 1 2 0\n1 0 0 0 1 1 1 0 0\n$EndEntities\n";
  const std::vector<Row> rows = {
      {"tetrahedra.msh", header + entities + nodes("1") + elements("1 1 4 8 5", "2 1 2 4 5\n", 3, 4),
       ":38: volume 1 holds 4-node tetrahedra; the seepage solver needs 8-node hexahedra"},
      {"no_group.msh", header + entities_without_volume_group + nodes("1") + elements("1 1 4 8 5", cube),
       ":38: volume 1 belongs to no physical group"},
      {"triangles.msh", header + entities + nodes("1") + elements("1 1 4 8", cube, 2),
       ":36: surface 1 of physical surface \"face\" holds 3-node triangles; the boundaries of a hexahedral mesh "
       "need 4-node quadrangles"},
      {"diagonal.msh", header + entities + nodes("1") + elements("1 1 2 7 8", cube),
       ":37: this quadrangle of physical surface \"face\" is not a face of any hexahedron"},
      {"stray_node.msh", header + entities + nodes("1") + elements("1 1 4 8 9", cube),
       ":37: this boundary quadrangle uses node 9, which no hexahedron uses"},
      {"flat.msh", header + entities + nodes("0") + elements("1 1 4 8 5", cube),
       "hexahedron 0 (first corner at (0, 0, 0)) is degenerate or inverted"},
      {"twisted.msh", header + entities + nodes("1") + elements("1 1 4 8 5", "2 1 2 3 4 5 6 8 7\n"),
       "hexahedron 0 (first corner at (0, 0, 0)) is degenerate or inverted"},
      {"twice.msh", header + entities + nodes("1") + elements("1 1 4 8 5", cube + "3 5 6 7 8 1 2 3 4\n"),
       ":40: this hexahedron has the nodes of the one at line 39: a cell given twice"},
  };
  for (const auto& row : rows) {
    INFO(row.name);
    CHECK_THROWS_WITH(seepage::read_gmsh3(write_file(dir / row.name, row.text)), Catch::Contains(row.message));
  }
  // A program that needs a plane mesh refuses a volume mesh, and the other way round.
  CHECK_THROWS_WITH(seepage::read_gmsh(dir / "good.msh"),
                    Catch::Contains("holds hexahedra, a volume mesh; a plane mesh (quadrangles) is needed here"));
  CHECK_THROWS_WITH(seepage::read_gmsh3(source_dir / "cases/verification/two_layers.msh"),
                    Catch::Contains("holds no hexahedra, a plane mesh; a volume mesh is needed here"));
}
