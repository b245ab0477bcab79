// Boundaries of the grid update: the walls on the physical domain's edges
// (fixed, roller, friction), their ghost nodes mirrored, and the rigid
// obstacles inside the grid (the tunnel's rock, supports).
#include <algorithm>
#include <array>
#include <numeric>

#include "mpm_solid/passes/ghosts.hpp"
#include "mpm_solid/solver.hpp"

namespace outburst::mpm {

namespace {

// A wall condition at one node; n is the unit normal pointing into the wall.
// Friction walls act only on nodes moving into them: the normal velocity is
// removed and the tangential one reduced by mu times that change. Returns the
// work done by friction (fixed and roller walls do none: the wall does not move).
template <int Dim>
double constrain(Vec<Dim>& v, const Vec<Dim>& n, const Wall& wall, double mass) {
  const double vn = v.dot(n);
  switch (wall.type) {
    case Wall::Type::fixed: v.setZero(); return 0;
    case Wall::Type::roller: v -= vn * n; return 0;
    case Wall::Type::friction: {
      if (vn <= 0) return 0;  // separating
      const Vec<Dim> vt = v - vn * n;
      const double slip = vt.norm();
      const double reduced = std::max(slip - wall.friction * vn, 0.0);
      v = slip > 0 ? Vec<Dim>(vt * (reduced / slip)) : Vec<Dim>::Zero();
      // Work of the friction impulse m (|v_t| - reduced) against the sliding.
      return mass * (slip - reduced) * reduced;
    }
    case Wall::Type::open: return 0;
  }
  return 0;
}

}  // namespace

template <int Dim>
void Solver<Dim>::find_obstacle_nodes() {
  const double tolerance = 1e-9 * grid_.h;
  obstacle_nodes_.assign(settings_.obstacles.size(), {});
  for (std::size_t k = 0; k < settings_.obstacles.size(); ++k) {
    const Obstacle<Dim>& o = settings_.obstacles[k];
    if (!(o.upper.array() > o.lower.array()).all())
      throw std::invalid_argument("an obstacle's upper corner must lie above and right of its lower corner");
    for (std::size_t i = 0; i < node_ij_.size(); ++i) {
      const Vec<Dim> x = grid_.node_position(node_ij_[i]);
      if ((x.array() < o.lower.array() - tolerance).any() || (x.array() > o.upper.array() + tolerance).any())
        continue;
      // Distances to the faces (left, right, bottom, top, and in 3D back,
      // front); the nearest sets the normal, and an edge or a corner (two or
      // three nearest) takes their diagonal.
      std::array<double, 2 * Dim> distance;
      for (int d = 0; d < Dim; ++d) {
        distance[2 * d] = x[d] - o.lower[d];
        distance[2 * d + 1] = o.upper[d] - x[d];
      }
      const double nearest = *std::min_element(distance.begin(), distance.end());
      Vec<Dim> n = Vec<Dim>::Zero();
      for (int f = 0; f < 2 * Dim; ++f)
        if (distance[f] <= nearest + tolerance) n += (f % 2 == 0 ? 1.0 : -1.0) * Vec<Dim>::Unit(f / 2);
      if (n.squaredNorm() == 0) continue;  // the centre of a square obstacle: no material reaches it
      obstacle_nodes_[k].push_back({i, n.normalized()});
    }
  }
}

// Walls sit on the physical domain's edges, on a row of nodes. The wall node
// takes the condition; ghost nodes beyond it mirror the node inside, with the
// constrained components reflected oddly, so the interpolated velocity meets the
// condition at the wall itself and not half a cell inside (which costs wide
// shape functions a whole order of accuracy). Obstacles act between the wall
// rows and the ghost rows: a ghost mirrors an obstacle's node as the obstacle
// leaves it (read before, its velocity changed where no energy book saw it).
// Only the active blocks, as this step's mapping collected them, are visited.
// Returns the work done by friction.
template <int Dim>
double Solver<Dim>::apply_walls(std::vector<Vec<Dim>>& velocity) const {
  double friction_work = 0;
  // The wall's condition at a node of its own motion: a wall row's, or a
  // ghost's beyond a friction wall, which keeps its own mass.
  const auto condition = [&](int side) {
    const Wall& wall = settings_.walls[side];
    Vec<Dim> normal = Vec<Dim>::Zero();
    normal[side / 2] = side % 2 == 0 ? -1 : 1;
    return [&wall, normal, &velocity, &friction_work, this](std::size_t i, std::size_t) {
      const double work = constrain(velocity[i], normal, wall, mass_[i]);
      // A ghost beyond a fixed or roller wall takes its mirror's motion
      // next, and its mass is folded into that node's: its work is not its own.
      if (counted_[i]) friction_work += work;
    };
  };
  // On the wall rows friction acts last: where a friction wall meets another
  // in 3D, the other's normal velocity is not slip along the friction wall
  // (in the plane the order makes no difference there).
  std::array<int, 2 * Dim> friction_last;
  std::iota(friction_last.begin(), friction_last.end(), 0);
  std::stable_partition(friction_last.begin(), friction_last.end(),
                        [&](int side) { return settings_.walls[side].type != Wall::Type::friction; });
  for (const int side : friction_last)
    if (settings_.walls[side].type != Wall::Type::open) over_ghost_layer(side, 0, condition(side));
  constrain_obstacles(velocity, friction_work);
  // Then the ghost rows: those beyond friction walls first, then those beyond
  // fixed and roller walls, row by row outward, so that every mirror is final
  // when it is read. Thin domains mirror one wall's ghosts in the other's;
  // where a fixed wall meets a friction one, the corner's ghosts mirror ghosts
  // beyond the friction wall, into which fold_ghosts put their masses, and
  // with which the energy books take them to share |dv| (grid_update).
  // Constrained in turn with the mirrors, depth by depth, a corner ghost
  // could copy a friction wall's ghost before friction slowed it, and
  // friction then constrained the copy as a node of its own, whose normal
  // velocity a fixed wall's reflection had turned: either way not its
  // mirror's reflection. (A roller's reflection keeps the normal velocity
  // and the slip's length: friction commutes with it.)
  for (int side = 0; side < 2 * Dim; ++side)
    if (settings_.walls[side].type == Wall::Type::friction)
      for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth) over_ghost_layer(side, depth, condition(side));
  mirror_ghosts(velocity);
  return friction_work;
}

// Obstacles act between the wall rows and the ghost rows (apply_walls).
template <int Dim>
void Solver<Dim>::constrain_obstacles(std::vector<Vec<Dim>>& velocity, double& friction_work) const {
  // Most of an obstacle's nodes lie deep in the rock, where no particle
  // reaches: outside the active runs, at rest, which every contact leaves
  // at rest. Both lists are in node order (find_obstacle_nodes goes along
  // the nodes), so a walk along the runs from the obstacle's first node
  // visits its active nodes in the order the full list would.
  const auto& runs = active_.runs();
  for (std::size_t k = 0; k < obstacle_nodes_.size(); ++k) {
    const Wall& contact = settings_.obstacles[k].contact;
    auto o = obstacle_nodes_[k].cbegin();
    const auto end = obstacle_nodes_[k].cend();
    if (o == end) continue;
    // The first run that ends beyond the obstacle's first node.
    auto run = std::upper_bound(runs.begin(), runs.end(), o->node, [](std::size_t i, const NodeRun& r) {
      return i < r.first + static_cast<std::size_t>(r.count);
    });
    for (; run != runs.end() && o != end; ++run) {
      o = std::lower_bound(o, end, run->first, [](const ObstacleNode& a, std::size_t i) { return a.node < i; });
      for (; o != end && o->node < run->first + static_cast<std::size_t>(run->count); ++o)
        if (const Vec<Dim>& v = velocity[o->node]; (v.array() != 0).any()) {
          const double work = constrain(velocity[o->node], o->normal, contact, mass_[o->node]);
          if (counted_[o->node]) friction_work += work;
        }
    }
  }
}

// Every ghost beyond a fixed or roller wall takes its mirror's velocity,
// reflected, row by row outward (apply_walls says why in that order).
template <int Dim>
void Solver<Dim>::mirror_ghosts(std::vector<Vec<Dim>>& velocity) const {
  for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth)
    for (int side = 0; side < 2 * Dim; ++side)
      if (const Wall::Type type = settings_.walls[side].type; mirrors(type))
        over_ghost_layer(side, depth, [&](std::size_t ghost, std::size_t mirror) {
          velocity[ghost] = passes::reflected<Dim>(velocity[mirror], side / 2, type);
        });
}

template <int Dim>
std::size_t Solver<Dim>::unmirrored_ghosts() const {
  std::size_t wrong = 0;
  for (int side = 0; side < 2 * Dim; ++side)
    if (const Wall::Type type = settings_.walls[side].type; mirrors(type))
      for (int depth = 1; depth <= Grid<Dim>::ghost; ++depth)
        over_ghost_layer(side, depth, [&](std::size_t ghost, std::size_t mirror) {
          for (const auto* field : {&velocity_, &velocity_new_})
            if ((*field)[ghost] != passes::reflected<Dim>((*field)[mirror], side / 2, type)) ++wrong;
        });
  return wrong;
}

#define INSTANTIATE(Dim)                                                                            \
  template void Solver<Dim>::find_obstacle_nodes();                                                 \
  template double Solver<Dim>::apply_walls(std::vector<Vec<Dim>>&) const;                           \
  template void Solver<Dim>::constrain_obstacles(std::vector<Vec<Dim>>&, double&) const;            \
  template void Solver<Dim>::mirror_ghosts(std::vector<Vec<Dim>>&) const;                           \
  template std::size_t Solver<Dim>::unmirrored_ghosts() const;
INSTANTIATE(2)
INSTANTIATE(3)
#undef INSTANTIATE

}  // namespace outburst::mpm
