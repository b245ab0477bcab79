// 3D scenes for seepage-fe (issue 21): the Gmsh reader's hexahedra, regions
// and boundaries; broken volume meshes refused with the line and what was
// expected; and the program itself, run on a box scene, against the library's
// Solver3 step for step, and on a Gmsh block against the same block generated.
#include <catch2/catch.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "common/hdf5_file.hpp"
#include "seepage_fe/mesh.hpp"
#include "seepage_fe/q1.hpp"
#include "seepage_fe/solver.hpp"

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

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

double volume_of(const seepage::Mesh3& m, int region = -1) {
  double v = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    if (region < 0 || m.cell_region[c] == region) v += seepage::q1::integrals(m.corners(c)).lumped.sum();
  return v;
}

// Runs seepage-fe on `scene` into `out`; its log goes to out.log.
int run_seepage_fe(const fs::path& scene, const fs::path& out) {
  const fs::path program = fs::path(OUTBURST_BINARY_DIR) / "seepage_fe" / "seepage-fe";
  const std::string command = fmt::format("'{}' '{}' -q --overwrite -o '{}' > '{}.log' 2>&1", program.string(),
                                          scene.string(), out.string(), out.string());
  const int status = std::system(command.c_str());
  INFO(read_file(out.string() + ".log"));
  REQUIRE(WIFEXITED(status));
  return WEXITSTATUS(status);
}

// One column of seepage_history.csv, as written (17 digits: each value back
// to the bit).
std::vector<double> history_column(const fs::path& out, const std::string& column) {
  std::ifstream in(out / "seepage_history.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream s(line); std::getline(s, line, ',');) names.push_back(line);
  const auto at = std::find(names.begin(), names.end(), column);
  REQUIRE(at != names.end());
  std::vector<double> values;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string cell;
    for (long k = 0; k <= at - names.begin(); ++k) std::getline(s, cell, ',');
    values.push_back(std::stod(cell));
  }
  return values;
}

// A field of the run's last snapshot.
std::vector<double> last_snapshot(const fs::path& out, const std::string& field) {
  fs::path last;
  for (const auto& entry : fs::directory_iterator(out)) {
    const auto name = entry.path().filename().string();
    if (name.rfind("seepage_0", 0) == 0 && entry.path().extension() == ".h5" && entry.path() > last)
      last = entry.path();
  }
  REQUIRE(!last.empty());
  return hdf5::H5Reader(last).read_doubles("/mesh/" + field);
}

// A law's scene text and the same in code: its key, each region's material
// keys (intact coal, softened coal ten times as conductive) and the model's
// materials. SI values, so that the library's side holds the very numbers the
// scene reader converts.
struct LawCase {
  seepage::Law law;
  std::string name, coal, softened;
  std::vector<seepage::Material> materials;
};
const std::vector<LawCase> laws{
    {seepage::Law::gas, "gas", "lambda = \"1e-18 m2/(Pa2 s)\"\ngas_content_coefficient = \"2e-3 Pa^-0.5\"\n",
     "lambda = \"1e-17 m2/(Pa2 s)\"\ngas_content_coefficient = \"2e-3 Pa^-0.5\"\n",
     {{1e-18, 2e-3, 3e6}, {1e-17, 2e-3, 3e6}}},
    {seepage::Law::linear, "linear",
     "permeability = \"1e-20 m2\"\nviscosity = \"1e-3 Pa s\"\nstorage_coefficient = \"1e-9 1/Pa\"\n",
     "permeability = \"1e-19 m2\"\nviscosity = \"1e-3 Pa s\"\nstorage_coefficient = \"1e-9 1/Pa\"\n",
     {{1e-20 / 1e-3, 1e-9, 3e6}, {1e-19 / 1e-3, 1e-9, 3e6}}}};

// The scene text both program tests run: a block of coal (or of a rock under
// the linear law) with a softened zone (where `softened_box` puts it on a
// generated mesh), drained through one face, its pressure falling over an
// hour, and fed through the opposite one.
std::string block_scene(const LawCase& law, const std::string& mesh, const std::string& softened_box,
                        const std::string& face, const std::string& far_end) {
  return R"toml([scene]
title = "3D scene test"
solvers = ["seepage"]
end_time = "1 d"

[output]
interval = "0.25 d"

[seepage]
law = ")toml" + law.name + R"toml("
time_step = "60 s"
time_step_growth = 1.3
max_time_step = "2 h"

[seepage.mesh]
)toml" + mesh + R"toml(
[[seepage.regions]]
name = "coal"
initial_pressure = "3e6 Pa"
)toml" + law.coal + R"toml(
[[seepage.regions]]
name = "softened"
initial_pressure = "3e6 Pa"
)toml" + law.softened + softened_box + R"toml(
[[seepage.boundaries]]
name = ")toml" + face + R"toml("
type = "pressure"
value = [["0 s", "3e6 Pa"], ["3600 s", "1e5 Pa"]]

[[seepage.boundaries]]
name = ")toml" + far_end + R"toml("
type = "flux"
value = "2e-7 m/s"
)toml";
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

TEST_CASE("seepage-fe runs a box scene to the library's nodal values, bit for bit", "[seepage][3d][program]") {
  for (const auto& law : laws) {
    INFO(law.name << " law");
    const fs::path dir = fresh_dir("box_scene_" + law.name);
    const auto scene = write_file(dir / "box.toml", block_scene(law, R"toml(type = "box"
size = ["2 m", "1 m", "1.5 m"]
cells = [8, 4, 6]
grading = [3, 1, 0.5]
)toml",
                                                                R"toml(box_min = ["0 m", "0 m", "0.5 m"]
box_max = ["0.5 m", "1 m", "1 m"]
)toml",
                                                                "left", "right"));
    REQUIRE(run_seepage_fe(scene, dir / "out") == 0);

    // The same problem built in code, stepped as the program's history says
    // it stepped.
    seepage::BoxMeshSpec spec;
    spec.size = {2.0, 1.0, 1.5};
    spec.cells = {8, 4, 6};
    spec.grading = {3.0, 1.0, 0.5};
    spec.regions = {{"coal", true, {}, {}}, {"softened", false, {0.0, 0.0, 0.5}, {0.5, 1.0, 1.0}}};
    seepage::Model model;
    model.law = law.law;
    model.materials = law.materials;
    model.boundary_conditions = {
        {"left", seepage::BoundaryCondition::Type::pressure, TimeFunction({{0.0, 3e6}, {3600.0, 1e5}})},
        {"right", seepage::BoundaryCondition::Type::flux, TimeFunction(2e-7)}};
    seepage::Solver3 solver(seepage::make_box_mesh(spec), model, {});
    const auto& region = solver.mesh().cell_region;
    const auto softened = std::count(region.begin(), region.end(), 1);
    CHECK(last_snapshot(dir / "out", "region") == std::vector<double>(region.begin(), region.end()));
    CHECK(softened > 0);
    const double initial = solver.unknown()[0];
    const auto steps = history_column(dir / "out", "dt_s");
    for (double h : steps) solver.advance(h);

    // The gas law writes its unknown P; both write p.
    const auto program_u = last_snapshot(dir / "out", law.law == seepage::Law::gas ? "P" : "p");
    REQUIRE(program_u.size() == solver.mesh().num_nodes());
    double largest = 0, drop = 0;
    for (std::size_t i = 0; i < program_u.size(); ++i) {
      largest = std::max(largest, std::abs(program_u[i] - solver.unknown()[i]));
      drop = std::max(drop, initial - solver.unknown()[i]);
    }
    const double stored = history_column(dir / "out", "stored_m3").back();
    std::printf("\nbox scene, %s law, %ld of 192 cells softened, %zu steps to t = %.6g s: largest |u_program - "
                "u_library| = %.3g (u fell by up to %.4g of %.4g); stored %.17g m3, the library's %.17g m3\n",
                law.name.c_str(), static_cast<long>(softened), steps.size(), solver.time(), largest, drop, initial,
                stored, solver.balance().stored);
    CHECK(solver.time() == Approx(86400.0).epsilon(1e-14));
    CHECK(drop > 0.1 * initial);  // the fluid has moved: equal values are not the initial ones
    CHECK(largest == 0.0);
    CHECK(stored == solver.balance().stored);

    // A 3D run's files: hexahedra in the index, balances in m3 (not per metre).
    const std::string xdmf = read_file(dir / "out" / "seepage.xdmf");
    CHECK_THAT(xdmf, Catch::Contains("TopologyType=\"Hexahedron\" NumberOfElements=\"192\""));
    CHECK(hdf5::H5Reader(dir / "out" / "seepage_mesh.h5").shape("/cells") == std::vector<std::size_t>{192, 8});
    CHECK(read_file(dir / "out" / "seepage_history.csv")
              .rfind("step,time_s,dt_s,substeps,cuts,iterations,stored_m3,inflow_flux_m3,inflow_left_m3,"
                     "balance_error_relative\n",
                     0) == 0);
  }
}

TEST_CASE("seepage-fe gives a Gmsh block the pressures of the same block generated", "[seepage][3d][program]") {
  const fs::path dir = fresh_dir("gmsh_scene");
  const auto gmsh = write_file(
      dir / "gmsh.toml",
      block_scene(laws[0], "type = \"gmsh\"\nfile = \"" + (source_dir / "cases/drainage_3d/block.msh").string() + "\"\n",
                  "", "face", "far_end"));
  const auto box = write_file(dir / "box.toml", block_scene(laws[0], R"toml(type = "box"
size = ["4 m", "2 m", "3 m"]
cells = [8, 4, 6]
)toml",
                                                            R"toml(box_min = ["0 m", "0 m", "0 m"]
box_max = ["1 m", "2 m", "3 m"]
)toml",
                                                            "left", "right"));
  REQUIRE(run_seepage_fe(gmsh, dir / "gmsh") == 0);
  REQUIRE(run_seepage_fe(box, dir / "box") == 0);

  // Nodes matched by position: Gmsh numbers them its own way.
  const auto gmsh_mesh = seepage::read_gmsh3(source_dir / "cases/drainage_3d/block.msh");
  seepage::BoxMeshSpec spec;
  spec.size = {4.0, 2.0, 3.0};
  spec.cells = {8, 4, 6};
  const auto box_mesh = seepage::make_box_mesh(spec);
  const auto at = [](const Eigen::Vector3d& x) {
    return std::array<long, 3>{std::lround(2 * x.x()), std::lround(2 * x.y()), std::lround(2 * x.z())};
  };
  std::map<std::array<long, 3>, std::size_t> box_node;
  for (std::size_t i = 0; i < box_mesh.num_nodes(); ++i) box_node[at(box_mesh.nodes[i])] = i;
  const auto P_gmsh = last_snapshot(dir / "gmsh", "P"), P_box = last_snapshot(dir / "box", "P");
  REQUIRE(P_gmsh.size() == gmsh_mesh.num_nodes());
  REQUIRE(P_box.size() == box_mesh.num_nodes());
  double largest = 0, scale = 0;
  for (std::size_t i = 0; i < gmsh_mesh.num_nodes(); ++i) {
    const auto j = box_node.find(at(gmsh_mesh.nodes[i]));
    REQUIRE(j != box_node.end());
    largest = std::max(largest, std::abs(P_gmsh[i] - P_box[j->second]));
    scale = std::max(scale, P_box[j->second]);
  }
  const double released_gmsh = -history_column(dir / "gmsh", "inflow_face_m3").back();
  const double released_box = -history_column(dir / "box", "inflow_left_m3").back();
  std::printf("\nGmsh block against the generated box: largest |P_gmsh - P_box| / max P = %.3g; gas released "
              "%.12g and %.12g m3\n",
              largest / scale, released_gmsh, released_box);
  CHECK(largest < 1e-9 * scale);
  CHECK(released_gmsh == Approx(released_box).epsilon(1e-9));
  CHECK(released_box > 1.0);
}
