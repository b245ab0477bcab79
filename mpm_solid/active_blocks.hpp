#pragma once
// The part of the grid a step can touch: the blocks of nodes (8 x 8 in 2D,
// 4 x 4 x 4 in 3D) that some particle's stencil reaches, and beside a fixed or
// roller wall the blocks its ghost nodes mirror into. Every nodal array is
// zero outside them, so the grid's own passes (clearing, summing the threads'
// copies, velocities, the update, the energy books, the walls, ghost folds
// and obstacles) run over these nodes only, and a mostly empty grid (a long
// tunnel, rock around a seam) costs in proportion to its particles.

#include <array>
#include <cstdint>
#include <vector>

#include "mpm_solid/grid.hpp"

namespace outburst::mpm {

// A contiguous run of nodes, the unit the grid's passes share out.
struct NodeRun {
  std::size_t first;
  int count;
};

template <int Dim>
class ActiveBlocks {
 public:
  // Nodes per block side: 64 nodes a block in either dimension. A stencil
  // (at most 3 nodes a side) spans at most two blocks along each axis.
  static constexpr int size = Dim == 2 ? 8 : 4;

  // mirrored[side]: whether the wall on that side (left, right, bottom, top,
  // and in 3D back, front) mirrors its ghost nodes (fixed and roller walls do).
  ActiveBlocks(const Grid<Dim>& grid, const std::array<bool, 2 * Dim>& mirrored, int threads);

  // Thread t's marks: a stencil whose lowest node is `base`, `support` nodes
  // per side, marks the blocks it reaches (set_reached, inlined in the loops).
  std::uint8_t* marks(int t) { return marks_[static_cast<std::size_t>(t)].data(); }
  // Blocks along x (and, in 3D, along x times along y): the strides of the
  // marks' index.
  const std::array<int, Dim - 1>& strides() const { return strides_; }
  template <int Support>
  static void set_reached(std::uint8_t* marks, const std::array<int, Dim - 1>& strides,
                          const std::array<int, Dim>& base) {
    const int x0 = base[0] / size, x1 = (base[0] + Support - 1) / size;
    const int y0 = base[1] / size, y1 = (base[1] + Support - 1) / size;
    if constexpr (Dim == 2) {
      const int row = strides[0];
      marks[y0 * row + x0] = marks[y0 * row + x1] = 1;
      marks[y1 * row + x0] = marks[y1 * row + x1] = 1;
    } else {
      const int z0 = base[2] / size, z1 = (base[2] + Support - 1) / size;
      for (const int z : {z0, z1})
        for (const int y : {y0, y1}) {
          const int first = z * strides[1] + y * strides[0];
          marks[first + x0] = marks[first + x1] = 1;
        }
    }
  }

  // Whether the block holding node ij is active.
  bool holds(const std::array<int, Dim>& ij) const {
    std::array<int, Dim> b;
    for (int d = 0; d < Dim; ++d) b[d] = ij[d] / size;
    return active_[block_index(b)];
  }

  // The threads' marks (cleared) become the active blocks, with the walls'
  // mirrors, and their nodes the runs below.
  void collect();

  // Contiguous runs of active nodes, in increasing node order.
  using Run = NodeRun;
  const std::vector<Run>& runs() const { return runs_; }
  // The same of the nodes the last collect() dropped (active before it, no
  // longer): what was left there is to be cleared.
  const std::vector<Run>& dropped() const { return dropped_; }
  std::size_t active_nodes() const { return active_nodes_; }
  std::size_t bytes() const;

 private:
  // The runs of the nodes of the blocks picked(flat block index) picks; their count.
  template <class Pick>
  std::size_t runs_of(Pick&& picked, std::vector<Run>& runs) const;
  std::size_t block_index(const std::array<int, Dim>& b) const {
    std::size_t flat = 0;
    for (int d = Dim - 1; d >= 0; --d)
      flat = flat * static_cast<std::size_t>(blocks_[d]) + static_cast<std::size_t>(b[d]);
    return flat;
  }

  std::array<int, Dim> nodes_, blocks_;
  std::array<int, Dim - 1> strides_;
  // For each mirroring wall: its axis and the node rows (along that axis) its
  // ghosts and their mirrors take, [from, to].
  struct Strip {
    int axis, from, to;
  };
  std::vector<Strip> strips_;
  std::vector<std::vector<std::uint8_t>> marks_;  // per thread, per block
  std::vector<std::uint8_t> active_, was_active_;  // per block: now, before the last collect
  std::vector<Run> runs_, dropped_;
  std::size_t active_nodes_ = 0;
};

}  // namespace outburst::mpm
