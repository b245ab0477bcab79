#include "mpm_solid/active_blocks.hpp"

#include <algorithm>

namespace outburst::mpm {

template <int Dim>
ActiveBlocks<Dim>::ActiveBlocks(const Grid<Dim>& grid, const std::array<bool, 2 * Dim>& mirrored, int threads) {
  std::size_t count = 1;
  for (int d = 0; d < Dim; ++d) {
    nodes_[d] = grid.nodes_along(d);
    blocks_[d] = (nodes_[d] + size - 1) / size;
    count *= static_cast<std::size_t>(blocks_[d]);
  }
  strides_[0] = blocks_[0];
  if constexpr (Dim == 3) strides_[1] = blocks_[0] * blocks_[1];
  marks_.assign(static_cast<std::size_t>(threads), std::vector<std::uint8_t>(count, 0));
  active_.assign(count, 0);
  was_active_.assign(count, 0);
  const int g = Grid<Dim>::ghost;
  for (int side = 0; side < 2 * Dim; ++side) {
    if (!mirrored[side]) continue;
    const int axis = side / 2, wall_row = side % 2 == 0 ? g : g + grid.cells[axis];
    strips_.push_back({axis, std::max(0, wall_row - g), std::min(nodes_[axis] - 1, wall_row + g)});
  }
}

template <int Dim>
void ActiveBlocks<Dim>::collect() {
  was_active_.swap(active_);
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
    std::array<int, Dim> b{};
    // Over the blocks of the strip's first layer; each stands for its column
    // across the strip.
    std::size_t layer = 1;
    for (int d = 0; d < Dim; ++d)
      if (d != s.axis) layer *= static_cast<std::size_t>(blocks_[d]);
    for (std::size_t flat = 0; flat < layer; ++flat) {
      std::size_t rest = flat;
      for (int d = 0; d < Dim; ++d) {
        if (d == s.axis) continue;
        b[d] = static_cast<int>(rest % static_cast<std::size_t>(blocks_[d]));
        rest /= static_cast<std::size_t>(blocks_[d]);
      }
      bool any = false;
      for (b[s.axis] = s.from / size; b[s.axis] <= s.to / size; ++b[s.axis]) any = any || active_[block_index(b)];
      if (!any) continue;
      for (b[s.axis] = s.from / size; b[s.axis] <= s.to / size; ++b[s.axis]) active_[block_index(b)] = 1;
    }
  }
  active_nodes_ = runs_of([this](std::size_t b) { return active_[b] != 0; }, runs_);
  const auto dropped = [this](std::size_t b) { return was_active_[b] != 0 && active_[b] == 0; };
  bool any = false;  // mostly none: the runs' walk over the rows is spared
  for (std::size_t b = 0; b < active_.size(); ++b) any = any || dropped(b);
  if (any)
    runs_of(dropped, dropped_);
  else
    dropped_.clear();
}

template <int Dim>
template <class Pick>
std::size_t ActiveBlocks<Dim>::runs_of(Pick&& picked, std::vector<Run>& runs) const {
  runs.clear();
  std::size_t nodes = 0;
  // Runs stay within a row of nodes along x: merged across rows, a body as
  // wide as the grid would make one run of every node, and the passes,
  // parallel over runs, one thread's work. The rows of a row of blocks share
  // one pattern of runs, [from, from + count) along x.
  std::vector<std::array<int, 2>> pattern;
  const int layers = Dim == 2 ? 1 : nodes_[Dim - 1];  // of nodes across z
  for (int k = 0; k < layers; ++k)
    for (int by = 0; by < blocks_[1]; ++by) {
      std::array<int, Dim> b{};
      b[1] = by;
      if constexpr (Dim == 3) b[2] = k / size;
      pattern.clear();
      for (b[0] = 0; b[0] < blocks_[0]; ++b[0]) {
        if (!picked(block_index(b))) continue;
        const int from = b[0] * size, count = std::min(nodes_[0], from + size) - from;
        if (!pattern.empty() && pattern.back()[0] + pattern.back()[1] == from)
          pattern.back()[1] += count;
        else
          pattern.push_back({from, count});
      }
      for (int j = by * size; j < std::min(nodes_[1], (by + 1) * size); ++j) {
        const std::size_t row =
            (static_cast<std::size_t>(k) * static_cast<std::size_t>(nodes_[1]) + static_cast<std::size_t>(j)) *
            static_cast<std::size_t>(nodes_[0]);
        for (const auto& [from, count] : pattern) {
          runs.push_back({row + static_cast<std::size_t>(from), count});
          nodes += static_cast<std::size_t>(count);
        }
      }
    }
  return nodes;
}

template <int Dim>
std::size_t ActiveBlocks<Dim>::bytes() const {
  std::size_t b = active_.capacity() + was_active_.capacity() + (runs_.capacity() + dropped_.capacity()) * sizeof(Run);
  for (const auto& m : marks_) b += m.capacity();
  return b;
}

template class ActiveBlocks<2>;
template class ActiveBlocks<3>;

}  // namespace outburst::mpm
