#include "mpm_solid/active_blocks.hpp"

#include <algorithm>

namespace outburst::mpm {

ActiveBlocks::ActiveBlocks(const Grid<2>& grid, const std::array<bool, 4>& mirrored, int threads) {
  for (int d = 0; d < 2; ++d) {
    nodes_[d] = grid.nodes_along(d);
    blocks_[d] = (nodes_[d] + size - 1) / size;
  }
  const std::size_t count = static_cast<std::size_t>(blocks_[0]) * static_cast<std::size_t>(blocks_[1]);
  marks_.assign(static_cast<std::size_t>(threads), std::vector<std::uint8_t>(count, 0));
  active_.assign(count, 0);
  const int g = Grid<2>::ghost;
  for (int side = 0; side < 4; ++side) {
    if (!mirrored[side]) continue;
    const int axis = side / 2, wall_row = side % 2 == 0 ? g : g + grid.cells[axis];
    strips_.push_back({axis, std::max(0, wall_row - g), std::min(nodes_[axis] - 1, wall_row + g)});
  }
}

void ActiveBlocks::collect() {
  std::fill(active_.begin(), active_.end(), 0);
  for (auto& m : marks_)
    for (std::size_t b = 0; b < m.size(); ++b) {
      active_[b] |= m[b];
      m[b] = 0;
    }
  // A ghost node beside a wall takes its mirror's velocity, and folds its
  // mass onto it: where a block of the strip along the wall is active, so is
  // the rest of the strip across it.
  for (const Strip& s : strips_) {
    const int across = 1 - s.axis;
    for (int k = 0; k < blocks_[across]; ++k) {
      std::array<int, 2> b{};
      b[across] = k;
      bool any = false;
      for (b[s.axis] = s.from / size; b[s.axis] <= s.to / size; ++b[s.axis])
        any = any || active_[static_cast<std::size_t>(b[1] * blocks_[0] + b[0])];
      if (!any) continue;
      for (b[s.axis] = s.from / size; b[s.axis] <= s.to / size; ++b[s.axis])
        active_[static_cast<std::size_t>(b[1] * blocks_[0] + b[0])] = 1;
    }
  }
  runs_.clear();
  active_nodes_ = 0;
  for (int j = 0; j < nodes_[1]; ++j) {
    const std::size_t row = static_cast<std::size_t>(j) * static_cast<std::size_t>(nodes_[0]);
    for (int bx = 0; bx < blocks_[0]; ++bx) {
      if (!active_[static_cast<std::size_t>((j / size) * blocks_[0] + bx)]) continue;
      const int from = bx * size, count = std::min(nodes_[0], from + size) - from;
      // Runs stay within a row: merged across rows, a body as wide as the
      // grid would make one run of every node, and the passes, parallel
      // over runs, one thread's work.
      if (from > 0 && !runs_.empty() &&
          runs_.back().first + static_cast<std::size_t>(runs_.back().count) == row + from)
        runs_.back().count += count;
      else
        runs_.push_back({row + static_cast<std::size_t>(from), count});
      active_nodes_ += static_cast<std::size_t>(count);
    }
  }
}

std::size_t ActiveBlocks::bytes() const {
  std::size_t b = active_.capacity() + runs_.capacity() * sizeof(Run);
  for (const auto& m : marks_) b += m.capacity();
  return b;
}

}  // namespace outburst::mpm
