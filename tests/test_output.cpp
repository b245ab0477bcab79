// Output files: complete or absent, never truncated; provenance recorded.
#include <catch2/catch.hpp>

#include <sys/resource.h>

#include <algorithm>
#include <csignal>
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
  series.add_mesh("mesh", {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 3}, output::CellShape::quadrilateral);
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
  CHECK_THAT(xdmf, Catch::Contains("TopologyType=\"Quadrilateral\" NumberOfElements=\"1\""));
  CHECK_THAT(xdmf, Catch::Contains("Dimensions=\"1 4\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">run_mesh.h5:/cells"));
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

TEST_CASE("a scene path with bytes XML cannot hold is percent-encoded in the index", "[output]") {
  const auto dir = fresh_dir("odd_path");
  // Before: written raw, the index was not XML and ParaView read no points.
  const std::string path = "/data/sc\xff\x01" "ene/100%/\xe7\x85\xa4 \xed\xa0\x80 \"a\"&<b>.toml";
  output::RunInfo info{"test", "0.0", path, "", {}, "SI"};
  output::FieldSeries series(dir, "run", info);
  series.add_point_grid("particles");
  output::Snapshot snap(0);
  snap.set_points("particles", {0.5, 0.5, 0});
  series.write(snap);
  const std::string xdmf = read(series.index_path());
  // Control characters, bytes that are not UTF-8 (0xff, a surrogate's
  // encoding) and '%' encoded; a character (U+7164) and markup as XML has them.
  CHECK_THAT(xdmf, Catch::Contains("Value=\"/data/sc%FF%01ene/100%25/\xe7\x85\xa4 %ED%A0%80 &quot;a&quot;&amp;&lt;b&gt;.toml\""));
  CHECK(std::all_of(xdmf.begin(), xdmf.end(), [](char c) { return static_cast<unsigned char>(c) >= 0x20 || c == '\n'; }));
}

TEST_CASE("a hexahedral mesh is written with its 8 corners per cell and indexed as hexahedra", "[output]") {
  const auto dir = fresh_dir("hexahedra");
  output::RunInfo info{"test", "0.0", "scene.toml", "", {}, "SI"};
  output::FieldSeries series(dir, "run", info);
  // Two unit cubes side by side along x.
  std::vector<double> xyz;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) xyz.insert(xyz.end(), {1.0 * i, 1.0 * j, 1.0 * k});
  // Node (i, j, k) is (k * 2 + j) * 3 + i.
  const std::vector<std::int64_t> cells{0, 1, 4, 3, 6, 7, 10, 9, 1, 2, 5, 4, 7, 8, 11, 10};
  series.add_mesh("mesh", xyz, cells, output::CellShape::hexahedron);
  output::Snapshot snap(0.0);
  snap.add("mesh", {"region", output::Center::cell, 1, "", {0, 1}});
  series.write(snap);
  const std::string xdmf = read(series.index_path());
  CHECK_THAT(xdmf, Catch::Contains("TopologyType=\"Hexahedron\" NumberOfElements=\"2\""));
  CHECK_THAT(xdmf, Catch::Contains("Dimensions=\"2 8\" NumberType=\"Int\" Precision=\"8\" Format=\"HDF\">run_mesh.h5:/cells"));
  CHECK_THAT(xdmf, Catch::Contains("Dimensions=\"12 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">run_mesh.h5:/nodes"));
  hdf5::H5Reader r(dir / "run_mesh.h5");
  CHECK(r.shape("/cells") == std::vector<std::size_t>{2, 8});
  CHECK(r.shape("/nodes") == std::vector<std::size_t>{12, 3});
}

TEST_CASE("a snapshot that cannot be finished (a full disk) fails with a clear error and leaves nothing",
          "[output]") {
  const auto dir = fresh_dir("full_disk");
  // The disk "fills" at 1 kB: files may not grow past it, and a write beyond
  // returns an error (EFBIG) instead of killing the process with SIGXFSZ.
  rlimit before{};
  getrlimit(RLIMIT_FSIZE, &before);
  const auto handler = std::signal(SIGXFSZ, SIG_IGN);
  const rlimit small{1024, before.rlim_max};
  setrlimit(RLIMIT_FSIZE, &small);
  std::string message;
  {
    hdf5::H5Writer w(dir / "snapshot.h5");
    // 8 kB, which HDF5 used to hold in its cache and write as the file closed.
    w.write("/p", std::vector<double>(1000, 1.0), "Pa");
    try {
      w.commit();
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    // Before: the close failed, commit() threw with the file still open, and
    // this destructor closed it again: SIGSEGV inside HDF5.
  }
  setrlimit(RLIMIT_FSIZE, &before);
  std::signal(SIGXFSZ, handler);
  CHECK_THAT(message, Catch::Contains("cannot write " + (dir / "snapshot.h5").string() + ": File too large (") &&
                          Catch::Contains("MB free on its disk)"));
  CHECK(fs::is_empty(dir));
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

TEST_CASE("series listed together list a time only once each of them has written it", "[output]") {
  const auto dir = fresh_dir("together");
  output::RunInfo info{"test", "0.0", "scene.toml", "", {}, "SI"};
  output::FieldSeries first(dir / "a", "first", info), second(dir / "b", "second", info);
  first.add_point_grid("particles");
  second.add_point_grid("particles");
  first.list_with_others();
  second.list_with_others();
  const auto snapshot = [](double t) {
    output::Snapshot s(t);
    s.set_points("particles", {0.5, 0.5, 0});
    return s;
  };
  const auto times_listed = [](const output::FieldSeries& s) {
    const std::string xdmf = read(s.index_path());
    std::size_t n = 0;
    for (auto at = xdmf.find("<Time "); at != std::string::npos; at = xdmf.find("<Time ", at + 1)) ++n;
    return n;
  };
  first.write(snapshot(0));
  second.write(snapshot(0));
  CHECK_FALSE(fs::exists(first.index_path()));  // written, not yet listed
  output::publish({&first, &second});
  CHECK(times_listed(first) == 1);
  CHECK(times_listed(second) == 1);
  // The second series cannot write its next snapshot (its folder is gone): the
  // first one's index must not list that time either. Before, the coupled
  // run's seepage.xdmf listed 5 times beside a particles.xdmf with 4.
  first.write(snapshot(1));
  fs::remove_all(dir / "b");
  CHECK_THROWS(second.write(snapshot(1)));
  CHECK(times_listed(first) == 1);
}
