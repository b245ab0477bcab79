#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "seepage_fe/cell_locator.hpp"
#include "seepage_fe/sampling.hpp"
#include "seepage_fe/mesh.hpp"
#include "seepage_fe/q1.hpp"
#include "seepage_fixtures.hpp"

using namespace outburst::seepage;
namespace fs = std::filesystem;

namespace {

const fs::path source_dir = OUTBURST_SOURCE_DIR;

double total_area(const Mesh& m) {
  double area = 0;
  for (const auto& c : m.cells) {
    const auto integrals = q1::integrals(q1::Corners{m.nodes[c[0]], m.nodes[c[1]], m.nodes[c[2]], m.nodes[c[3]]});
    area += integrals.lumped.sum();
  }
  return area;
}

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("outburst_test_" + name);
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST_CASE("a generated mesh is graded as asked and paints regions by box", "[seepage][mesh]") {
  StructuredMeshSpec spec;
  spec.size = {10, 2};
  spec.cells = {20, 4};
  spec.grading = {10, 1};
  spec.regions = {{"all", true, {}, {}}, {"right", false, {6, -1}, {11, 3}}};
  const Mesh m = make_structured_mesh(spec);
  CHECK(m.num_nodes() == 21 * 5);
  CHECK(total_area(m) == Approx(20.0).epsilon(1e-12));
  const double first = m.nodes[1].x() - m.nodes[0].x();
  const double last = m.nodes[20].x() - m.nodes[19].x();
  CHECK(last / first == Approx(10.0).epsilon(1e-12));
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const double xc = 0.25 * (m.nodes[m.cells[c][0]].x() + m.nodes[m.cells[c][2]].x() +
                              m.nodes[m.cells[c][1]].x() + m.nodes[m.cells[c][3]].x());
    CHECK(m.cell_region[c] == (xc > 6 ? 1 : 0));
  }
  REQUIRE(m.boundary("left"));
  CHECK(m.boundary("left")->faces.size() == 4);
  CHECK(m.boundary("top")->faces.size() == 20);
}

TEST_CASE("the Gmsh reader keeps quads, regions and boundaries", "[seepage][mesh]") {
  const Mesh m = read_gmsh(source_dir / "cases/verification/two_layers.msh");
  CHECK(m.region_names.size() == 2);
  CHECK(m.region_index("soft") >= 0);
  CHECK(m.region_index("hard") >= 0);
  CHECK(total_area(m) == Approx(10.0).epsilon(1e-12));
  REQUIRE(m.boundary("inlet"));
  double inlet_length = 0;
  for (const auto& e : m.boundary("inlet")->faces) inlet_length += (m.nodes[e[1]] - m.nodes[e[0]]).norm();
  CHECK(inlet_length == Approx(1.0).epsilon(1e-12));
  // Every cell of region "soft" lies left of the interface x = 4.
  for (std::size_t c = 0; c < m.num_cells(); ++c)
    for (int k = 0; k < 4; ++k)
      if (m.cell_region[c] == m.region_index("soft")) CHECK(m.nodes[m.cells[c][k]].x() <= 4 + 1e-12);
}

TEST_CASE("broken meshes are rejected with the line and what was expected", "[seepage][mesh]") {
  const std::string header = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  const std::string entities =
      "$PhysicalNames\n1\n2 1 \"coal\"\n$EndPhysicalNames\n"
      "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 1 1 0\n$EndEntities\n";
  const std::string nodes =
      "$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n";
  const std::string quad = "$Elements\n1 1 1 1\n2 1 3 1\n1 1 2 3 4\n$EndElements\n";
  // The good file first, so the table below tests only what each row breaks.
  REQUIRE(read_gmsh(write_temp("good.msh", header + entities + nodes + quad)).num_cells() == 1);

  struct Row {
    std::string name, text, message;
  };
  const std::vector<Row> rows = {
      {"v22.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", ":2: MSH format 2.2 is not supported"},
      {"binary.msh", "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n", "binary MSH is not supported"},
      {"triangles.msh",
       header + entities + nodes + "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n",
       "holds 3-node triangles; the seepage solver needs 4-node quadrangles"},
      {"no_group.msh",
       header + "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 0 0\n$EndEntities\n" + nodes + quad,
       "belongs to no physical group"},
      {"missing_node.msh",
       header + entities + nodes + "$Elements\n1 1 1 1\n2 1 3 1\n1 1 2 3 9\n$EndElements\n",
       "uses node 9, which $Nodes does not define"},
      {"bad_number.msh", header + entities + "$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 x 0\n",
       ":20: expected y (a finite number), got 'x'"},
      {"truncated.msh", header + entities + "$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n",
       "the file ends early"},
      {"not_msh.msh", "hello\n", "no $MeshFormat section"},
      {"clockwise_bowtie.msh",
       header + entities + nodes + "$Elements\n1 1 1 1\n2 1 3 1\n1 1 3 2 4\n$EndElements\n",
       "is degenerate or not convex"},
      // Before: std::bad_alloc, "cannot create std::vector larger than max_size()",
      // a tag wrapped to another entity's, and a cell counted twice.
      {"huge_count.msh", header + entities + "$Nodes\n1 1000000000000 1 4\n2 1 0 1000000000000\n1\n",
       ":14: the number of nodes in the block is 1000000000000, more than the rest of the file"},
      {"negative_count.msh", header + entities + "$Nodes\n1 4 1 4\n2 1 0 -1\n",
       ":14: the number of nodes in the block is -1; expected a count >= 0"},
      {"count_beyond_long.msh", header + entities + "$Nodes\n1 4 1 4\n2 1 0 99999999999999999999\n",
       "the number of nodes in the block 99999999999999999999 is out of range"},
      {"tag_beyond_int.msh",
       header + "$PhysicalNames\n1\n2 1 \"coal\"\n$EndPhysicalNames\n"
                "$Entities\n0 0 1 0\n4294967297 0 0 0 1 1 0 1 1 0\n$EndEntities\n" + nodes + quad,
       ":10: an entity tag 4294967297 is out of range (at most 2147483647)"},
      {"repeated_quad.msh",
       header + entities + nodes + "$Elements\n1 2 1 2\n2 1 3 2\n1 1 2 3 4\n2 2 3 4 1\n$EndElements\n",
       ":28: this quadrangle has the nodes of the one at line 27: a cell given twice"},
  };
  for (const auto& row : rows) {
    INFO(row.name);
    CHECK_THROWS_WITH(read_gmsh(write_temp(row.name, row.text)), Catch::Contains(row.message));
  }
}

TEST_CASE("points are located in their cell on generated and Gmsh meshes", "[seepage][mesh]") {
  const Mesh m = read_gmsh(source_dir / "cases/verification/two_layers.msh");
  const CellLocator locator(m);
  // Every cell's centre is found in that cell, and maps back to itself.
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const q1::Corners x{m.nodes[m.cells[c][0]], m.nodes[m.cells[c][1]], m.nodes[m.cells[c][2]],
                        m.nodes[m.cells[c][3]]};
    const Eigen::Vector2d centre = 0.25 * (x[0] + x[1] + x[2] + x[3]);
    const auto hit = locator.locate(centre);
    REQUIRE(hit);
    const auto n = q1::shape(hit->reference.x(), hit->reference.y());
    Eigen::Vector2d back = Eigen::Vector2d::Zero();
    const auto& hc = m.cells[hit->cell];
    for (int a = 0; a < 4; ++a) back += n[a] * m.nodes[hc[a]];
    CHECK((back - centre).norm() < 1e-12);
  }
  CHECK(locator.buckets() <= m.num_cells());
  CHECK_FALSE(locator.locate({-0.1, 0.5}));
  CHECK_FALSE(locator.locate({5.0, 1.2}));
  CHECK(locator.locate({10.0, 1.0}));  // a corner of the domain
}

TEST_CASE("a locator over a very thin mesh has no more buckets than cells", "[seepage][mesh]") {
  // Found by fuzzing: a mesh 3e-22 m high asked for 1.6e8 buckets, 50 s and
  // gigabytes before the first step.
  StructuredMeshSpec spec;
  spec.size = {30, 3e-22};
  spec.cells = {150, 6};
  spec.regions = {{"all", true, {}, {}}};
  const Mesh m = make_structured_mesh(spec);
  const CellLocator locator(m);
  CHECK(locator.buckets() <= m.num_cells());
  REQUIRE(locator.locate({15, 1e-22}));
}

TEST_CASE("points are located in small cells far from the origin", "[seepage][mesh]") {
  // Found by the outburst's convergence study: Newton's step in reference
  // coordinates had to fall below 1e-13, under its own roundoff (eps |x| /
  // cell) in cells of 1/8 m beyond x = 32 m, so their particles lay in no cell:
  // no pore pressure, and the cells read as open space.
  const double cell = GENERATE(0.125, 1.0 / 6, 0.01);
  const double far = GENERATE(45.0, 1e3, -2e3);
  const double aspect = GENERATE(1.0, 100.0);  // thin cells: the roundoff goes as the thinnest side
  StructuredMeshSpec spec;
  spec.origin = {far, -far};
  spec.size = {40 * cell * aspect, 20 * cell};
  spec.cells = {40, 20};
  spec.regions = {{"all", true, {}, {}}};
  const Mesh m = make_structured_mesh(spec);
  const CellLocator locator(m);
  int found = 0, points = 0;
  for (int i = 0; i < 160; ++i)
    for (int j = 0; j < 80; ++j, ++points) {
      const Eigen::Vector2d x = spec.origin + cell * Eigen::Vector2d(aspect * (i + 0.5) / 4, (j + 0.5) / 4);
      const auto hit = locator.locate(x);
      if (!hit) continue;
      ++found;
      const auto& c = m.cells[hit->cell];
      const auto n = q1::shape(hit->reference.x(), hit->reference.y());
      Eigen::Vector2d back = Eigen::Vector2d::Zero();
      for (int a = 0; a < 4; ++a) back += n[a] * m.nodes[c[a]];
      CHECK((back - x).norm() < 1e-9 * cell + 1e-13 * std::abs(far));
      // The locator maps these rectangles directly; Newton's map, which
      // other cells take, must find the points too.
      const auto newton = q1::inverse_map(m.corners(static_cast<std::size_t>(hit->cell)), x);
      REQUIRE(newton);
      CHECK((*newton - hit->reference).lpNorm<Eigen::Infinity>() < 1e-9);
    }
  INFO("cells of " << cell << " m by " << aspect * cell << " m at " << far << " m");
  CHECK(found == points);
}

namespace {

// A structured mesh, sheared into parallelograms, with every third interior
// node moved off the grid: cells of both kinds side by side.
Mesh sheared_mesh_with_moved_nodes() {
  StructuredMeshSpec spec;
  spec.size = {4, 2};
  spec.cells = {8, 4};
  spec.regions = {{"all", true, {}, {}}};
  Mesh m = make_structured_mesh(spec);
  for (auto& x : m.nodes) x.x() += 0.3 * x.y();
  int moved = 0;
  for (std::size_t k = 0; k < m.nodes.size(); ++k) {
    auto& x = m.nodes[k];
    const bool interior = x.y() > 1e-9 && x.y() < 2 - 1e-9 && x.x() - 0.3 * x.y() > 1e-9 &&
                          x.x() - 0.3 * x.y() < 4 - 1e-9;
    if (interior && k % 3 == 0) {
      x += Eigen::Vector2d(0.07, -0.05);
      ++moved;
    }
  }
  REQUIRE(moved > 0);
  return m;
}

}  // namespace

TEST_CASE("parallelograms are located by their affine map, other cells by Newton's, with the same answers",
          "[seepage][mesh]") {
  const Mesh m = sheared_mesh_with_moved_nodes();
  const CellLocator locator(m);
  int parallelograms = 0, general = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const q1::Corners x = m.corners(c);
    ((x[0] - x[1] + x[2] - x[3]).norm() < 1e-12 ? parallelograms : general)++;
    // Points at and inside the cell's corners and edges, mapped forward.
    for (const double xi : {-1.0, -0.6, 0.0, 0.999, 1.0})
      for (const double eta : {-1.0, -0.3, 0.5, 1.0}) {
        const auto n = q1::shape(xi, eta);
        Eigen::Vector2d point = Eigen::Vector2d::Zero();
        for (int a = 0; a < 4; ++a) point += n[a] * x[a];
        int hint = static_cast<int>(c);
        const auto hit = locator.locate(point, &hint);
        REQUIRE(hit);
        CHECK(hit->cell == static_cast<int>(c));
        CHECK((hit->reference - Eigen::Vector2d(xi, eta)).lpNorm<Eigen::Infinity>() < 1e-12);
        // Without a hint the bucket search finds a cell holding the point.
        const auto found = locator.locate(point);
        REQUIRE(found);
        const auto back = q1::shape(found->reference.x(), found->reference.y());
        Eigen::Vector2d mapped = Eigen::Vector2d::Zero();
        for (int a = 0; a < 4; ++a) mapped += back[a] * m.corners(static_cast<std::size_t>(found->cell))[a];
        CHECK((mapped - point).norm() < 1e-12);
      }
    // Just outside each edge's midpoint: not in this cell.
    const Eigen::Vector2d centre = 0.25 * (x[0] + x[1] + x[2] + x[3]);
    for (int a = 0; a < 4; ++a) {
      const Eigen::Vector2d mid = 0.5 * (x[a] + x[(a + 1) % 4]);
      int hint = static_cast<int>(c);
      const auto hit = locator.locate(mid + 1e-6 * (mid - centre), &hint);
      if (hit) CHECK(hit->cell != static_cast<int>(c));
    }
  }
  CHECK(parallelograms > 0);
  CHECK(general > 0);
}

TEST_CASE("a field sampled in a parallelogram by its constant inverse Jacobian equals the isoparametric sample",
          "[seepage][mesh]") {
  const Mesh m = sheared_mesh_with_moved_nodes();
  const Sampler sampler(m);
  // A field with no special form: neither linear nor bilinear in x and y.
  Eigen::VectorXd u(static_cast<Eigen::Index>(m.num_nodes()));
  for (std::size_t k = 0; k < m.num_nodes(); ++k)
    u[static_cast<Eigen::Index>(k)] = std::sin(3 * m.nodes[k].x()) + m.nodes[k].y() * m.nodes[k].y();
  int affine = 0;
  for (std::size_t c = 0; c < m.num_cells(); ++c) {
    const q1::Corners x = m.corners(c);
    for (const double xi : {-1.0, -0.4, 0.3, 1.0})
      for (const double eta : {-1.0, 0.2, 0.9}) {
        const auto n = q1::shape(xi, eta);
        Eigen::Vector2d point = Eigen::Vector2d::Zero();
        for (int a = 0; a < 4; ++a) point += n[a] * x[a];
        int hint = static_cast<int>(c);
        const auto got = sampler.sample(u, point, &hint);
        REQUIRE(got);
        REQUIRE(hint == static_cast<int>(c));
        const auto expected = q1::sample(x, m.cells[c], u, Eigen::Vector2d(xi, eta));
        CHECK(std::abs(got->value - expected.value) < 1e-12);
        CHECK((got->gradient - expected.gradient).norm() < 1e-11 * (1 + expected.gradient.norm()));
        affine += (x[0] - x[1] + x[2] - x[3]).norm() < 1e-12;
      }
  }
  CHECK(affine > 0);
}

TEST_CASE("a batch of points sampled over SIMD lanes gives each point its own sample, bit for bit",
          "[seepage][mesh]") {
  // Parallelograms, which the lanes take, and moved cells, which they leave
  // to the one-point search. The mesh spans x in [0, 4.6], y in [0, 2].
  const Mesh m = sheared_mesh_with_moved_nodes();
  outburst::testing::check_batch_samples(m, Eigen::Vector2d(-0.3, -0.2), Eigen::Vector2d(4.9, 2.2), true);
}
