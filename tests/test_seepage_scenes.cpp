// Every shipped seepage scene is valid: read fully, no unknown keys.
#include <catch2/catch.hpp>

#include <filesystem>

#include "common/program.hpp"
#include "seepage_fe/scene_reader.hpp"

using namespace outburst;

TEST_CASE("shipped seepage scenes are valid", "[scene][cases]") {
  int checked = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(std::string(OUTBURST_SOURCE_DIR) + "/cases")) {
    if (entry.path().extension() != ".toml") continue;
    auto doc = scene::Document::load(entry.path());
    auto root = doc->root();
    const auto header = read_scene_header(root);
    if (header.solvers != std::vector<std::string>{"seepage"}) continue;
    INFO(entry.path().string());
    REQUIRE_NOTHROW(seepage::read_setup(*root.table("seepage", "", true)));
    REQUIRE_NOTHROW(doc->reject_unused());
    ++checked;
  }
  CHECK(checked >= 1);
}
