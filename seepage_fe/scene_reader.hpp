#pragma once
// Reads the [seepage] section of a scene into a mesh, a model, solver settings
// and the time-step control. Run `seepage-fe SCENE --explain` to see every key a
// scene uses with its value, unit, default and meaning.

#include <variant>

#include "common/scene.hpp"
#include "seepage_fe/mesh.hpp"
#include "seepage_fe/model.hpp"

namespace outburst::seepage {

struct TimeStepControl {
  double first;        // [s]
  double growth;       // each step is this factor longer than the last
  double maximum;      // [s]
};

template <int Dim>
struct SetupOf {
  MeshOf<Dim> mesh;
  Model model;
  Settings settings;
  TimeStepControl steps{};
};
using Setup = SetupOf<2>;
using Setup3 = SetupOf<3>;

// A scene's dimension is its mesh's: a "structured" rectangle or a Gmsh file
// of quadrangles is plane, a "box" or a Gmsh file of hexahedra 3D.
// own_time_steps: read time_step and its growth (false when a coupling window
// sets the steps, so a coupled scene does not carry keys nothing uses).
std::variant<Setup, Setup3> read_any_setup(const scene::Table& seepage, bool own_time_steps = true);

// Steps a run to end_time takes under this control (output times aside).
double estimated_steps(const TimeStepControl& steps, double end_time);
// Refuses, at seepage.time_step, a run of more steps than any run may take.
void check_run_length(const scene::Table& seepage, const TimeStepControl& steps, double end_time,
                      double output_interval);

}  // namespace outburst::seepage
