// The scene file format (common/scene.hpp): bad input gets a clear error
// naming the file, the line, the key and what was expected (a table of broken
// scenes, each with the message it must produce); overrides; --explain. What
// the programs' readers make of whole scenes: test_scene_readers.cpp.
#include <catch2/catch.hpp>

#include "broken_scenes.hpp"
#include "common/program.hpp"
#include "seepage_fe/scene_reader.hpp"

using namespace outburst;
using testing::replace;

namespace {

// What seepage-fe does with a scene before running it.
void read_seepage_scene(const std::string& text, const std::vector<std::string>& overrides = {}) {
  auto doc = scene::Document::parse(text, "broken.toml", overrides);
  auto root = doc->root();
  const auto header = read_scene_header(root);
  require_solvers(root, header, {"seepage"}, "seepage-fe");
  seepage::read_any_setup(*root.table("seepage", "", true));
  doc->reject_unused();
}

const char* valid = R"toml([scene]
solvers = ["seepage"]
end_time = "1 d"
[seepage]
time_step = "1 h"
[seepage.mesh]
size = ["10 m", "1 m"]
cells = [10, 1]
[[seepage.regions]]
name = "coal"
lambda = "0.1 m2/(MPa2 d)"
gas_content_coefficient = "2 MPa^-0.5"
initial_pressure = "3 MPa"
[[seepage.boundaries]]
name = "left"
type = "pressure"
value = "0.1 MPa"
)toml";

}  // namespace

TEST_CASE("the reference scene is valid", "[scene]") { REQUIRE_NOTHROW(read_seepage_scene(valid)); }

TEST_CASE("broken scenes are rejected with file, line, key and what was expected", "[scene]") {
  const std::vector<testing::BrokenScene> rows = {
      {replace(valid, "time_step = \"1 h\"", "time_stepp = \"1 h\""),
       {"broken.toml", "seepage.time_step", "required key is missing"}},
      {replace(valid, "[seepage]\n", "[seepage]\ncolour = \"red\"\n"),
       {"broken.toml:5:10", "seepage.colour", "unknown key", "time_step"}},
      {replace(valid, "end_time = \"1 d\"", "end_time = 86400"),
       {"broken.toml:3:12", "scene.end_time", "expected a time with its unit", "bare number"}},
      {replace(valid, "end_time = \"1 d\"", "end_time = \"1 m\""),
       {"broken.toml:3:12", "scene.end_time", "expected a time", "which is a length"}},
      {replace(valid, "initial_pressure = \"3 MPa\"", "initial_pressure = \"-3 MPa\""),
       {"broken.toml:13:20", "seepage.regions[0].initial_pressure", "must be > 0"}},
      {replace(valid, "lambda = \"0.1 m2/(MPa2 d)\"", "lambda = \"0.1 m2/(MPa d)\""),
       {"seepage.regions[0].lambda", "expected a gas conductivity", "mobility"}},
      {replace(valid, "cells = [10, 1]", "cells = [10, 0]"),
       {"broken.toml:8:9", "seepage.mesh.cells", "must be >= 1"}},
      {replace(valid, "cells = [10, 1]", "cells = [10]"),
       {"seepage.mesh.cells", "expected an array of 2 integers"}},
      {replace(valid, "type = \"pressure\"", "type = \"presure\""),
       {"broken.toml:16:8", "seepage.boundaries[0].type", "expected one of \"pressure\", \"flux\""}},
      {replace(valid, "name = \"left\"", "name = \"face\""),
       {"seepage.boundaries[0].name", "no boundary \"face\"", "left, right, bottom, top"}},
      {replace(valid, "solvers = [\"seepage\"]", "solvers = [\"seepage\", \"mpm\"]"),
       {"broken.toml:2:11", "scene.solvers", "seepage-fe runs only seepage", "'mpm'"}},
      {replace(valid, "solvers = [\"seepage\"]", "solvers = [\"seepage\", \"fluid\"]"),
       {"scene.solvers", "\"fluid\" is not one of"}},
      {replace(valid, "value = \"0.1 MPa\"", "value = [[\"0 s\", \"3 MPa\"], [\"0 s\", \"1 MPa\"]]"),
       {"seepage.boundaries[0].value", "must increase strictly"}},
      {replace(valid, "[seepage]\ntime_step", "[seepage]\nlaw = \"linear\"\ntime_step"),
       {"seepage.regions[0].permeability", "required key is missing"}},
      {replace(valid, "gas_content_coefficient = \"2 MPa^-0.5\"",
               "gas_content_coefficient = \"1.25 m3/(t MPa^0.5)\""),
       {"seepage.regions[0].coal_density", "required key is missing"}},
      {replace(valid, "[[seepage.regions]]", "[[seepage.region]]"),
       {"seepage.regions", "give at least one [[seepage.regions]]"}},
      {replace(valid, "end_time = \"1 d\"", "end_time = \"1 d\"\nrest_fraction = 0.01"),
       {"broken.toml:4:17", "scene.rest_fraction", "needs the mpm solver"}},
      {replace(valid, "[scene]", "[scene\n"), {"broken.toml:1:", "not valid TOML"}},
      {replace(valid, "[seepage.mesh]\n", "[seepage.mesh]\ntype = \"gmsh\"\nfile = \"nowhere.msh\"\n"),
       {"seepage.mesh.file", "does not exist"}},
      // Integers are checked against the int they are stored in (before: a 1 x 1
      // mesh, and -1294967296 Newton iterations).
      {replace(valid, "cells = [10, 1]", "cells = [4294967297, 1]"),
       {"broken.toml:8:9", "seepage.mesh.cells", "each entry must be >= 1 and <= 2147483647, got 4294967297"}},
      {replace(valid, "[seepage]\n", "[seepage]\nmax_iterations = 3000000000\n"),
       {"broken.toml:5:18", "seepage.max_iterations", "must be >= 1 and <= 1000, got 3000000000"}},
      {replace(valid, "cells = [10, 1]", "cells = [100000, 100000]"),
       {"seepage.mesh.cells", "1e+10 nodes, more than the 2147483647 a mesh may have"}},
      {replace(valid, "cells = [10, 1]", "cells = [40000, 40000]"),
       {"seepage.mesh.cells", "would need at least", "GB, more than this machine's"}},
      {replace(valid, "[seepage.mesh]\n", "[seepage.mesh]\ntype = \"gmsh\"\nfile = \".\"\n"),
       {"seepage.mesh.file", "\".\" is a directory", "expected a file"}},
      {replace(valid, "time_step = \"1 h\"", "time_step = \"1 h\"\nmax_time_step = \"10 min\""),
       {"broken.toml:6:17", "seepage.max_time_step", "600 s is below the first step, time_step = 3600 s"}},
      {replace(valid, "value = \"0.1 MPa\"\n",
               "value = \"0.1 MPa\"\n[[seepage.boundaries]]\nname = \"left\"\ntype = \"flux\"\nvalue = \"0 m/s\"\n"),
       {"broken.toml:19:8", "seepage.boundaries[1].name", "boundary \"left\" already has a condition",
        "seepage.boundaries[0]"}},
      {replace(valid, "[[seepage.boundaries]]",
               "[[seepage.regions]]\nname = \"all\"\nlambda = \"1 m2/(MPa2 d)\"\n"
               "gas_content_coefficient = \"2 MPa^-0.5\"\ninitial_pressure = \"3 MPa\"\n[[seepage.boundaries]]"),
       {"seepage.regions[0].name", "region \"coal\" holds no cell", "a later region covers the whole mesh"}},
      {replace(valid, "end_time = \"1 d\"", "end_time = \"1e308 d\""),
       {"broken.toml:3:12", "scene.end_time", "\"1e308 d\" overflows"}},
      // A misspelt key or section is named beside the key it leaves missing.
      {replace(valid, "time_step = \"1 h\"", "time_stepp = \"1 h\""),
       {"seepage.time_step", "required key is missing",
        "the scene has 'seepage.time_stepp' (broken.toml:5:14), which nothing reads: misspelt?"}},
      {replace(valid, "[seepage.mesh]", "[seepage.mesj]"),
       {"seepage.mesh", "required section [seepage.mesh] is missing", "'seepage.mesj'", "misspelt?"}},
  };
  testing::check_refused(rows, [](const std::string& scene) { read_seepage_scene(scene); });
}

TEST_CASE("command-line overrides replace scene keys and are checked like them", "[scene]") {
  REQUIRE_NOTHROW(read_seepage_scene(valid, {"seepage.time_scheme=\"backward_euler\""}));
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.time_scheme=\"rk4\""}),
                    Catch::Contains("--set: key 'seepage.time_scheme': expected one of"));
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.time_step=1 h"}),
                    Catch::Contains("strings need quotes"));
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.timestep=\"1 h\""}),
                    Catch::Contains("unknown key"));
  // Keys inside arrays of tables are addressed by index.
  REQUIRE_NOTHROW(read_seepage_scene(valid, {"seepage.regions[0].initial_pressure=\"5 MPa\""}));
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.regions[0].initial_pressure=\"-5 MPa\""}),
                    Catch::Contains("--set: key 'seepage.regions[0].initial_pressure': must be > 0"));
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.regions[3].lambda=\"1 m2/(MPa2 d)\""}),
                    Catch::Contains("no table regions[3]"));
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.regions[x].lambda=\"1 m2/(MPa2 d)\""}),
                    Catch::Contains("'x' is not an index"));
  // An index beyond 2^64 (before: "stoul").
  CHECK_THROWS_WITH(read_seepage_scene(valid, {"seepage.regions[18446744073709551617].lambda=\"1 m2/(MPa2 d)\""}),
                    Catch::Contains("the scene has no table regions[18446744073709551617]"));
}

TEST_CASE("a scene nested deeper than 32 levels is refused where it goes deep, before it is parsed", "[scene]") {
  // Before: a key or header of 35,000 parts (70 kB) overflowed the stack, in
  // this reader's recursion or, at 300,000, in toml++'s.
  const auto parts = [](int n, const std::string& name = "a") {
    std::string key = name;
    for (int i = 1; i < n; ++i) key += "." + name;
    return key;
  };
  const auto parse = [](const std::string& text) { scene::Document::parse(text, "deep.toml"); };
  const std::string start = "[scene]\ntitle = \"x\"\n";
  CHECK_THROWS_WITH(parse(start + parts(35000) + " = 1\n"),
                    Catch::Contains("deep.toml:3:1: key 'a.a.a.a.a") && Catch::Contains("a.a....':") &&
                        Catch::Contains("nested 35001 levels deep") && Catch::Contains("at most 32"));
  CHECK_THROWS_WITH(parse(start + "[" + parts(35000) + "]\nb = 1\n"),
                    Catch::Contains("deep.toml:3:1") && Catch::Contains("nested 35000 levels deep"));
  CHECK_THROWS_WITH(parse(start + "x = " + std::string(200000, '[') + std::string(200000, ']') + "\n"),
                    Catch::Contains("deep.toml:3:35: key 'x': nested 33 or more levels deep"));
  std::string inline_tables = "x = ";
  for (int i = 0; i < 100000; ++i) inline_tables += "{a = ";
  CHECK_THROWS_WITH(parse(start + inline_tables + "\n"),
                    Catch::Contains("deep.toml:3:156: key 'x': nested 33 or more levels deep"));
  CHECK_THROWS_WITH(scene::Document::parse(start, "deep.toml", {parts(35000) + "=1"}),
                    Catch::Contains("--set: key 'a.a.a") && Catch::Contains("nested 35000 levels deep"));
  CHECK_THROWS_WITH(scene::Document::parse(start, "deep.toml", {"scene.title=" + std::string(100000, '[')}),
                    Catch::Contains("--set: key 'scene.title': nested 33 or more levels deep"));
  // Each table, part of a key, array and inline table is a level: 32 pass.
  CHECK_NOTHROW(parse(parts(32) + " = 1\n"));
  CHECK_THROWS_WITH(parse(parts(33) + " = 1\n"), Catch::Contains("nested 33 levels deep"));
  CHECK_NOTHROW(parse("[[x.y]]\n" + parts(30) + " = 1\n"));
  CHECK_THROWS_WITH(parse("[[x.y]]\n" + parts(31) + " = 1\n"), Catch::Contains("deep.toml:2:1") &&
                                                                  Catch::Contains("nested 33 levels deep"));
  CHECK_NOTHROW(parse("x = " + std::string(31, '[') + std::string(31, ']') + "\n"));
  CHECK_THROWS(parse("x = " + std::string(32, '[') + std::string(32, ']') + "\n"));
  CHECK_NOTHROW(parse("x = " + std::string(27, '[') + "{a.b = [[1], {c = 2}]}" + std::string(27, ']') + "\n"));
  CHECK_THROWS(parse("x = " + std::string(27, '[') + "{a.b = [[[1]], {c = 2}]}" + std::string(27, ']') + "\n"));
  // What strings, quoted keys, comments and multi-line strings hold is not
  // nesting, and dates and times are values like others.
  CHECK_NOTHROW(parse(start + "\"" + parts(100) + "\" = 1\n'" + parts(100, "b") + "' = 2\n"));
  CHECK_NOTHROW(parse(start + "s = \"" + std::string(100, '[') + " \\\" " + parts(100) + "\"  # " + parts(100) +
                      " [[[[\n"));
  CHECK_NOTHROW(parse(start + "m = \"\"\"\n" + parts(100) + " = [[[[[\n\\\n" + std::string(100, '{') + "\"\"\"\n" +
                      "l = '''" + std::string(100, '[') + "'''\nd = [1979-05-27 07:32:00, 1979-05-27T00:32:00-07:00]\n" +
                      "t = { a = { b = 1 }, c = [ { d = 2 }, [] ], e = {} }\n"));
  // Lines are counted across multi-line strings.
  CHECK_THROWS_WITH(parse(start + "m = \"\"\"\na\nb\\\nc\"\"\"\nn = '''\nx\n'''\n" + parts(40) + " = 1\n"),
                    Catch::Contains("deep.toml:10:1"));
}

TEST_CASE("a scene that is not a regular file is refused before it is read", "[scene]") {
  // Before: /dev/zero was read without end.
  CHECK_THROWS_WITH(scene::Document::load("/dev/zero"), Catch::Contains("/dev/zero: the scene is a device"));
  CHECK_THROWS_WITH(scene::Document::load(OUTBURST_SOURCE_DIR), Catch::Contains("the scene is a directory"));
}

TEST_CASE("explain lists every key read, marking defaults", "[scene]") {
  auto doc = scene::Document::parse(valid, "valid.toml");
  auto root = doc->root();
  read_scene_header(root);
  seepage::read_any_setup(*root.table("seepage", "", true));
  const std::string text = doc->explain();
  CHECK_THAT(text, Catch::Contains("seepage.time_scheme = \"bdf2\""));
  CHECK_THAT(text, Catch::Contains("(default)"));
  CHECK_THAT(text, Catch::Contains("seepage.regions[0].lambda = 0.1 m2/(MPa2 d)"));
}

TEST_CASE("explain as JSON gives each key with what it expects, its choices and its range", "[scene]") {
  auto doc = scene::Document::parse(valid, "valid.toml");
  auto root = doc->root();
  read_scene_header(root);
  seepage::read_any_setup(*root.table("seepage", "", true));
  const std::string json = doc->explain_json();
  CHECK_THAT(json, Catch::StartsWith("{"));
  CHECK_THAT(json, Catch::Contains(R"("key" : "seepage.time_scheme")"));
  CHECK_THAT(json, Catch::Contains(R"("backward_euler")"));
  CHECK_THAT(json, Catch::Contains(R"("expects" : "one of")"));
  CHECK_THAT(json, Catch::Contains(R"("default" : true)"));
  // Every key read appears once.
  std::size_t keys = 0;
  for (auto at = json.find(R"("key" :)"); at != std::string::npos; at = json.find(R"("key" :)", at + 1)) ++keys;
  CHECK(keys == doc->records().size());
}
