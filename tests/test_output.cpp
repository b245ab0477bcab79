// Output files: complete or absent, never truncated; provenance recorded.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/field_output.hpp"
#include "common/hdf5_file.hpp"

using namespace outburst;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("outburst_test_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("an HDF5 file that was never committed leaves nothing behind", "[output]") {
  const auto dir = fresh_dir("uncommitted");
  {
    hdf5::H5Writer w(dir / "result.h5");
    const std::vector<double> data(1000, 1.0);
    w.write("/fields/p", data, "Pa");
    // The run dies here: the writer is destroyed without commit().
  }
  CHECK(fs::is_empty(dir));
}

TEST_CASE("a series writes mesh, snapshots and an index listing only complete snapshots",
          "[output]") {
  const auto dir = fresh_dir("series");
  output::RunInfo info{"test", "0.0", "scene.toml", "[scene]\ntitle = \"x\"\n", {"a.b=1"}, "SI"};
  output::FieldSeries series(dir, "run", info);
  series.add_quad_mesh("mesh", {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 3});
  series.add_point_grid("particles");
  for (int k = 0; k < 3; ++k) {
    output::Snapshot snap(0.5 * k);
    snap.add("mesh", {"p", output::Center::node, 1, "Pa", {1.0 * k, 2, 3, 4}});
    snap.add("mesh", {"flux", output::Center::cell, 3, "m/s", {1, 0, 0}});
    snap.set_points("particles", {0.5, 0.5, 0, 0.25, 0.25, 0});
    snap.add("particles", {"damage", output::Center::node, 1, "", {0.1, 0.2}});
    series.write(snap);
  }
  const std::string xdmf = read(series.index_path());
  CHECK_THAT(xdmf, Catch::Contains("run_000002.h5:/mesh/p"));
  CHECK_THAT(xdmf, Catch::Contains("TopologyType=\"Polyvertex\""));
  CHECK_THAT(xdmf, Catch::Contains("run_000002.h5:/particles/connectivity"));
  CHECK_THAT(xdmf, Catch::Contains("<Time Value=\"1\"/>"));
  for (const auto& entry : fs::directory_iterator(dir))
    CHECK(entry.path().string().find(".partial") == std::string::npos);

  hdf5::H5Reader r(dir / "run_000002.h5");
  CHECK(r.read_doubles("/mesh/p") == std::vector<double>{2, 2, 3, 4});
  CHECK(r.shape("/mesh/flux") == std::vector<std::size_t>{1, 3});
  CHECK(r.string_attribute("/", "scene_text") == info.scene_text);
  CHECK(r.string_attribute("/", "version") == "0.0");
  CHECK(r.string_attribute("/mesh/p", "unit") == "Pa");
  CHECK(r.number_attribute("/", "time") == 1.0);
}

TEST_CASE("a scene text of any size is kept in every output file", "[output]") {
  const auto dir = fresh_dir("big_scene");
  // Before: over 64 kB the fixed-length attribute could not be written.
  std::string text = "[scene]\ntitle = \"big\"\n";
  while (text.size() < 300000) text += "# a long comment, as a big polygon or a long note would make it\n";
  output::RunInfo info{"test", "0.0", "scene.toml", text, {}, "SI"};
  output::FieldSeries series(dir, "run", info);
  series.add_point_grid("particles");
  output::Snapshot snap(0);
  snap.set_points("particles", {0.5, 0.5, 0});
  series.write(snap);
  hdf5::H5Reader r(dir / "run_000000.h5");
  CHECK(r.string_attribute("/", "scene_text") == text);
  CHECK(r.string_attribute("/", "program") == "test");
}
