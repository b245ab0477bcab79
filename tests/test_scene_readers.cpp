// What the programs' scene readers make of whole scenes: every shipped scene
// is valid (read fully, no unknown keys), and the coupled scene's checks
// across its solvers (cells read as open space, meshes past the grid, the
// fields the solid sends). The scene file format itself: test_scene_format.cpp.
#include <catch2/catch.hpp>

#include <filesystem>

#include "common/program.hpp"
#include "coupler/model.hpp"
#include "coupler/scene_reader.hpp"
#include "mpm_solid/scene_reader.hpp"
#include "seepage_fe/scene_reader.hpp"

using namespace outburst;

TEST_CASE("shipped scenes are valid", "[scene][cases]") {
  int checked = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(std::string(OUTBURST_SOURCE_DIR) + "/cases")) {
    // study.toml and schemes.toml are study specs (cases/study.py checks them), not scenes.
    const auto name = entry.path().filename();
    if (entry.path().extension() != ".toml" || name == "study.toml" || name == "schemes.toml") continue;
    INFO(entry.path().string());
    auto doc = scene::Document::load(entry.path());
    auto root = doc->root();
    const auto header = read_scene_header(root);
    const bool coupled = header.solvers.size() == 2;
    for (const auto& solver : header.solvers) {
      // Either may be plane or 3D; a coupled scene's seepage takes its time
      // steps from the coupling's windows.
      if (solver == "seepage") REQUIRE_NOTHROW(seepage::read_any_setup(*root.table("seepage", "", true), !coupled));
      if (solver == "mpm") {
        const auto mpm_table = root.table("mpm", "", true);
        if (mpm::scene_dimension(*mpm_table) == 2)
          REQUIRE_NOTHROW(mpm::read_setup<2>(*mpm_table));
        else
          REQUIRE_NOTHROW(mpm::read_setup<3>(*mpm_table));
      }
    }
    if (coupled) REQUIRE_NOTHROW(coupling::read_coupling(*root.table("coupling", "", true)));
    REQUIRE_NOTHROW(doc->reject_unused());
    ++checked;
  }
  CHECK(checked >= 2);
}

TEST_CASE("a coupled scene whose particles leave seepage cells reading as open space is refused", "[scene][coupling]") {
  const std::string scene = std::string(OUTBURST_SOURCE_DIR) + "/cases/outburst/outburst.toml";
  const auto setup = [&](const std::string& per_cell) {
    auto doc = scene::Document::load(scene, {"mpm.bodies[0].particles_per_cell=" + per_cell});
    return coupling::read_coupled_setup<2>(doc->root());
  };
  // 1/3 m cells: 2 and 3 particles per cell fill every 0.5 m seepage cell to
  // 100 % and 79 % at least; 1 per cell (1/3 m apart) some to 44 %, below
  // open_below = 0.5.
  REQUIRE_NOTHROW(setup("2"));
  REQUIRE_NOTHROW(setup("3"));
  REQUIRE_THROWS_WITH(setup("1"), Catch::Contains("mpm.grid.cell_size") &&
                                      Catch::Contains("the narrowest seepage cell, 0.5 m wide") &&
                                      Catch::Contains("holds 1 row of particles") && Catch::Contains("as little as 44 %"));
}

TEST_CASE("a coupled scene whose seepage mesh reaches past the MPM grid is refused", "[scene][coupling]") {
  const std::string scene = std::string(OUTBURST_SOURCE_DIR) + "/cases/gas_face/gas_face.toml";
  const auto setup = [&](const std::string& origin) {
    auto doc = scene::Document::load(scene, {"seepage.mesh.origin=" + origin});
    return coupling::read_coupled_setup<2>(doc->root());
  };
  REQUIRE_NOTHROW(setup(R"(["2 m", "1 m"])"));
  // Before: accepted, every cell read open and the gas left in the first window.
  CHECK_THROWS_WITH(setup(R"(["20 m", "1 m"])"), Catch::Contains("--set: key 'seepage.mesh.origin'") &&
                                                      Catch::Contains("reaches 18 m past the grid's right edge (x = 6 m)"));
  CHECK_THROWS_WITH(setup(R"(["-1 m", "1 m"])"), Catch::Contains("1 m past the grid's left edge (x = 0 m)"));
}

TEST_CASE("the solid sends the seepage only the fields the scene's physics use", "[scene][coupling]") {
  const auto sent = [](const std::string& extra) {
    auto doc = scene::Document::parse("window = \"1 ms\"\n" + extra, "coupling.toml");
    const auto setup = coupling::read_coupling(doc->root());
    std::vector<std::string> names;
    for (const auto& c : setup.scheme.to_first) names.push_back(c.field);
    return names;
  };
  using V = std::vector<std::string>;
  CHECK(sent("") == V{"occupancy", "stress", "damage"});
  CHECK(sent("permeability_coupling = false") == V{"occupancy"});
  CHECK(sent("biot_storage = true\npermeability_coupling = false") == V{"occupancy", "dilatation"});
  CHECK(sent("scheme = \"one_way\"").empty());
}
