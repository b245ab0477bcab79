// Every shipped scene is valid: read fully by its solvers, no unknown keys.
#include <catch2/catch.hpp>

#include <filesystem>

#include "common/program.hpp"
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
      if (solver == "seepage") REQUIRE_NOTHROW(seepage::read_setup(*root.table("seepage", "", true), !coupled));
      if (solver == "mpm") REQUIRE_NOTHROW(mpm::read_setup(*root.table("mpm", "", true)));
    }
    if (coupled) REQUIRE_NOTHROW(coupling::read_coupling(*root.table("coupling", "", true)));
    REQUIRE_NOTHROW(doc->reject_unused());
    ++checked;
  }
  CHECK(checked >= 2);
}
