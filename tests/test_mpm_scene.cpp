// Bad MPM input gets a located error before any particle exists: overlapping
// or overhanging bodies, tracers off the grid, self-crossing polygons, sizes
// beyond memory and runs that could not finish.
#include <catch2/catch.hpp>

#include "broken_scenes.hpp"
#include "common/program.hpp"
#include "mpm_solid/scene_reader.hpp"

using namespace outburst;
using testing::replace;

namespace {

// What mpm-solid does with a scene before it builds the solver.
void read_mpm_scene(const std::string& text) {
  auto doc = scene::Document::parse(text, "broken.toml");
  auto root = doc->root();
  const auto header = read_scene_header(root);
  const auto mpm_table = root.table("mpm", "", true);
  const auto setup = mpm::read_setup<2>(*mpm_table);
  doc->reject_unused();
  mpm::check_run_length(*mpm_table, setup, header.end_time);
}

const char* valid = R"toml([scene]
solvers = ["mpm"]
end_time = "0.02 s"
[mpm]
tracers = [["1.1 m", "0.9 m"]]
[mpm.grid]
size = ["4 m", "2 m"]
cell_size = "0.25 m"
[[mpm.materials]]
name = "coal"
model = "drucker_prager"
density = "1600 kg/m3"
youngs_modulus = "6 GPa"
poisson_ratio = 0.3
cohesion = "1 MPa"
friction_angle = "30 deg"
[[mpm.bodies]]
material = "coal"
box_min = ["1 m", "0 m"]
box_max = ["2 m", "1 m"]
[[mpm.bodies]]
material = "coal"
polygon = [["2 m", "0 m"], ["3 m", "0 m"], ["3 m", "1 m"], ["2 m", "1 m"]]
)toml";

}  // namespace

TEST_CASE("the reference MPM scene is valid", "[scene][mpm]") { REQUIRE_NOTHROW(read_mpm_scene(valid)); }

TEST_CASE("broken MPM scenes are refused with the key and what is wrong", "[scene][mpm]") {
  // Each was accepted before, silently changing the run or hanging it.
  const std::vector<testing::BrokenScene> rows = {
      {replace(valid, "box_max = [\"2 m\", \"1 m\"]",
               "box_max = [\"2 m\", \"1 m\"]\n[[mpm.bodies]]\nmaterial = \"coal\"\nbox_min = [\"1.5 m\", \"0.5 m\"]\n"
               "box_max = [\"2.5 m\", \"1 m\"]"),
       {"broken.toml:23:11", "mpm.bodies[1].box_min", "the body overlaps mpm.bodies[0] at (1.5625, 0.5625) m",
        "would be doubled"}},
      {replace(valid, "box_max = [\"2 m\", \"1 m\"]", "box_max = [\"2 m\", \"6 m\"]"),
       {"broken.toml:20:11", "mpm.bodies[0].box_max", "the body reaches 4 m past the grid's top edge (y = 2 m)",
        "[0, 4] x [0, 2] m"}},
      {replace(valid, "[\"3 m\", \"1 m\"], [\"2 m\", \"1 m\"]", "[\"2 m\", \"1 m\"], [\"3 m\", \"1 m\"]"),
       {"mpm.bodies[1].polygon", "the polygon crosses itself", "edge from vertex 1 meets its edge from vertex 3"}},
      {replace(valid, "tracers = [[\"1.1 m\", \"0.9 m\"]]", "tracers = [[\"1.1 m\", \"0.9 m\"], [\"5 m\", \"1 m\"]]"),
       {"broken.toml:5:11", "mpm.tracers", "the tracer at (5, 1) m lies outside the grid"}},
      {replace(valid, "[mpm]\n", "[mpm]\ncourant = 0\n"), {"mpm.courant", "must be > 0 and <= 1, got 0"}},
      {replace(valid, "cell_size = \"0.25 m\"", "cell_size = \"0.0001 m\""),
       {"broken.toml:8:13", "mpm.grid.cell_size", "a grid of 4e+04 x 2e+04 cells", "more than this machine's"}},
      {replace(valid, "friction_angle = \"30 deg\"", "friction_angle = \"90 deg\""),
       {"mpm.materials[0].friction_angle", "must be >= 0 deg and < 85.9437 deg, got \"90 deg\""}},
      {replace(valid, "friction_angle = \"30 deg\"", "friction_angle = \"30 m\""),
       {"mpm.materials[0].friction_angle", "expected an angle with its unit", "which is a length"}},
      {replace(valid, "youngs_modulus = \"6 GPa\"", "youngs_modulus = \"1e30 GPa\""),
       {"mpm.courant", "an estimated", "MPM steps", "material \"coal\"", "more than the 1e+08 a run may take"}},
      {replace(valid, "[mpm]\n", "[mpm]\ntime_step = \"1e-30 s\"\n"),
       {"broken.toml:5:13", "mpm.time_step", "an estimated 2e+28 MPM steps"}},
      {replace(valid, "[[mpm.bodies]]\nmaterial = \"coal\"\nbox_min",
               "[[mpm.bodies]]\nmaterial = \"coal\"\nparticles_per_cell = 4294967298\nbox_min"),
       {"mpm.bodies[0].particles_per_cell", "must be >= 1 and <= 8, got 4294967298"}},
  };
  testing::check_refused(rows, [](const std::string& scene) { read_mpm_scene(scene); });
}
