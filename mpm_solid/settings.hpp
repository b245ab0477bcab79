#pragma once
// What a scene sets for the MPM step: the update scheme, the shape
// functions, the velocity transfer, damping, and the boundaries (walls,
// obstacles, platens) with the quasi-static settling stage before t = 0.

#include <array>
#include <optional>
#include <vector>

#include "mpm_solid/particles.hpp"

namespace outburst::mpm {

enum class Scheme { usf, usl, musl };
enum class ShapeKind { linear, gimp, bspline };

// Cells a crack's strain spreads over: a jump in nodal velocity between two
// nodes strains the one cell between them under linear shapes, and under GIMP
// too while the particles' domains tile the cells (none reaches into its
// neighbour's cell); under quadratic B-splines the gradient of the jump is a
// tent two cells wide, and every particle under it breaks as the crack opens.
// A crack band is as wide as this (tests/test_mpm_fracture.cpp measures it).
constexpr int crack_cells(ShapeKind shape) { return shape == ShapeKind::bspline ? 2 : 1; }

struct Wall {
  enum class Type { open, fixed, roller, friction };
  Type type = Type::open;
  double friction = 0;  // Coulomb coefficient (friction walls)
};

// Fixed and roller walls mirror their ghost nodes (fold_ghosts, apply_walls).
inline bool mirrors(Wall::Type type) { return type == Wall::Type::fixed || type == Wall::Type::roller; }

// A rigid, fixed rectangle (a box in 3D) inside the grid (the tunnel's roof
// and floor rock, a support): grid nodes inside it or on its faces take its
// contact condition, with the normal of the nearest face. Faces on grid lines
// act exactly there; others act up to a cell inside the obstacle.
// A support holds material only while it settles (the unexcavated face): the
// dynamic stage starts without it.
template <int Dim>
struct Obstacle {
  Vec<Dim> lower, upper;
  Wall contact{Wall::Type::friction, 0};
  bool support = false;
};

// A rigid, massless, frictionless loading plate: the grid nodes in its box move
// together along `axis`, pushed by `force` and by what the material beneath
// pushes back; across that axis they move freely. Unlike a traction, the load
// shifts toward the stiffer part of the body as it deforms (Mandel's problem).
template <int Dim>
struct Platen {
  Vec<Dim> lower, upper;
  int axis = 1;
  double force = 0;  // along axis [N; N/m in 2D, per metre of depth]
  // Set: the plate moves at this speed along axis [m/s] whatever it takes
  // (displacement control, which can follow a load past its peak); `force`
  // is then unused.
  std::optional<double> velocity;
};

// The quasi-static stage before t = 0: in-situ stress and gravity brought to
// equilibrium with local damping, supports in place.
struct Settling {
  double duration = 0;  // [s]; 0: no stage
  double damping = 0.8;
};

template <int Dim>
struct Settings {
  Scheme scheme = Scheme::usf;
  // Quadratic B-splines by default: C1 gradients (no cell-crossing noise when
  // particles travel far) and the most accurate in the tests.
  ShapeKind shape = ShapeKind::bspline;
  // Velocity transfer: FLIP/PIC blend (1: pure FLIP, 0: pure PIC), or APIC
  // (affine particle-in-cell: PIC plus a velocity gradient per particle, which
  // conserves angular momentum without FLIP's noise).
  bool apic = false;
  double flip_fraction = 0.99;
  double courant = 0.3;
  Vec<Dim> gravity = Vec<Dim>::Zero();
  // Local (Cundall) damping coefficient for quasi-static stages: each nodal
  // force component loses alpha |f| against the node's motion. 0: off.
  double local_damping = 0;
  // Mass-proportional viscous damping c [1/s]: nodal force -c m v, taken
  // implicitly (stable for any c). Linear and smooth in the state, unlike the
  // local damping's sign switch: what an iterated coupling of a quasi-static
  // solid needs. 0: off.
  double viscous_damping = 0;
  // left, right, bottom, top (and in 3D back, front) of the physical domain:
  // the low and high face along each axis in turn
  std::array<Wall, 2 * Dim> walls;
  std::vector<Obstacle<Dim>> obstacles;
  std::vector<Platen<Dim>> platens;
  // Volumetric-locking remedy: replace each particle's dilatation rate tr(L) by
  // its volume-weighted average mapped to the nodes and back (nodal dilatation
  // smoothing), leaving the deviatoric rate alone. Near-incompressible
  // elasticity and plastic flow otherwise lock and checkerboard.
  bool smooth_dilatation = false;
  // Nodes lighter than this fraction of the mean particle mass are treated as
  // empty (no velocity): they would turn a finite force into a huge one.
  double empty_node_mass_fraction = 1e-6;
};

}  // namespace outburst::mpm
