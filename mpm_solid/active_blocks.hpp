#pragma once
// The part of the grid a step can touch: the blocks of B x B nodes that some
// particle's stencil reaches, and beside a fixed or roller wall the blocks its
// ghost nodes mirror into. Every nodal array is zero outside them, so the
// grid's own passes (clearing, summing the threads' copies, velocities, the
// update, the energy books) run over these nodes only, and a mostly empty grid
// (a long tunnel, rock around a seam) costs in proportion to its particles.

#include <array>
#include <cstdint>
#include <vector>

#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

class ActiveBlocks {
 public:
  static constexpr int size = 8;  // nodes per block side

  // mirrored[side]: whether the wall on that side (left, right, bottom, top)
  // mirrors its ghost nodes (fixed and roller walls do).
  ActiveBlocks(const Grid<2>& grid, const std::array<bool, 4>& mirrored, int threads);

  // Thread t's marks: a stencil whose lowest node is `base`, `support` nodes
  // per side, marks the blocks it reaches (set_reached, inlined in the loops).
  std::uint8_t* marks(int t) { return marks_[static_cast<std::size_t>(t)].data(); }
  int blocks_along_x() const { return blocks_[0]; }
  template <int Support>
  static void set_reached(std::uint8_t* marks, int blocks_along_x, const std::array<int, 2>& base) {
    const int x0 = base[0] / size, x1 = (base[0] + Support - 1) / size;
    const int y0 = base[1] / size, y1 = (base[1] + Support - 1) / size;
    marks[y0 * blocks_along_x + x0] = marks[y0 * blocks_along_x + x1] = 1;
    marks[y1 * blocks_along_x + x0] = marks[y1 * blocks_along_x + x1] = 1;
  }

  // The threads' marks (cleared) become the active blocks, with the walls'
  // mirrors, and their nodes the runs below.
  void collect();

  // Contiguous runs of active nodes, in increasing node order.
  struct Run {
    std::size_t first;
    int count;
  };
  const std::vector<Run>& runs() const { return runs_; }
  std::size_t active_nodes() const { return active_nodes_; }
  std::size_t bytes() const;

 private:
  std::array<int, 2> nodes_, blocks_;
  // For each mirroring wall: its axis and the node rows (along that axis) its
  // ghosts and their mirrors take, [from, to].
  struct Strip {
    int axis, from, to;
  };
  std::vector<Strip> strips_;
  std::vector<std::vector<std::uint8_t>> marks_;  // per thread, per block
  std::vector<std::uint8_t> active_;
  std::vector<Run> runs_;
  std::size_t active_nodes_ = 0;
};

}  // namespace outburst::mpm
