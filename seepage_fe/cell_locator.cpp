#include "seepage_fe/cell_locator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "seepage_fe/q1.hpp"

namespace outburst::seepage {

namespace {

// The affine map of a parallelogram (parallelepiped) to its reference cell,
// or nullopt if the cell is not one (to roundoff of its size).
std::optional<std::pair<Eigen::Vector2d, Eigen::Matrix2d>> affine_map(const std::array<Eigen::Vector2d, 4>& x,
                                                                      double size) {
  // x0 - x1 + x2 - x3 is the bilinear term's coefficient (times 4): zero,
  // to roundoff, for a parallelogram.
  if ((x[0] - x[1] + x[2] - x[3]).lpNorm<Eigen::Infinity>() > 1e-12 * size) return std::nullopt;
  Eigen::Matrix2d jacobian;  // d(x, y) / d(xi, eta), constant
  jacobian << 0.5 * (x[1] - x[0]), 0.5 * (x[3] - x[0]);
  return std::pair{Eigen::Vector2d(0.25 * (x[0] + x[1] + x[2] + x[3])), Eigen::Matrix2d(jacobian.inverse())};
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Matrix3d>> affine_map(const std::array<Eigen::Vector3d, 8>& x,
                                                                      double size) {
  Eigen::Matrix3d jacobian;  // from the edges leaving corner 0
  jacobian << 0.5 * (x[1] - x[0]), 0.5 * (x[3] - x[0]), 0.5 * (x[4] - x[0]);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& corner : x) centre += 0.125 * corner;
  for (int a = 0; a < 8; ++a) {
    const Eigen::Vector3d r(q1::hex_corner[a][0], q1::hex_corner[a][1], q1::hex_corner[a][2]);
    if ((centre + jacobian * r - x[a]).lpNorm<Eigen::Infinity>() > 1e-12 * size) return std::nullopt;
  }
  return std::pair{centre, Eigen::Matrix3d(jacobian.inverse())};
}

}  // namespace

template <int Dim>
CellLocatorOf<Dim>::CellLocatorOf(const MeshOf<Dim>& mesh) : mesh_(mesh) {
  Point lo = mesh.nodes.front(), hi = mesh.nodes.front();
  for (const auto& p : mesh.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // About one cell per bucket on average, in buckets matching the domain's
  // shape; never more buckets than cells, however thin the domain (a mesh
  // 3e-22 m high asked for 1.6e8 buckets).
  const Point extent = (hi - lo).cwiseMax(1e-12);
  const double cells = static_cast<double>(mesh.num_cells());
  if constexpr (Dim == 2) {
    const double aspect = extent.x() / extent.y();
    along_[0] = static_cast<int>(std::clamp(std::sqrt(cells * aspect), 1.0, cells));
    along_[1] = std::max(1, static_cast<int>(cells / along_[0]));
  } else {
    // Cubes of the volume per cell, each axis at least one bucket. An axis
    // held at one bucket (a thin slab) leaves the others too many: the
    // longest gives them back until there is at most one per cell.
    const double side = std::cbrt(extent.prod() / cells);
    double total = 1;
    for (int d = 0; d < Dim; ++d) {
      along_[d] = static_cast<int>(std::clamp(extent[d] / side, 1.0, cells));
      total *= along_[d];
    }
    while (total > cells) {
      const int d = static_cast<int>(std::max_element(along_.begin(), along_.end()) - along_.begin());
      total /= along_[d];
      along_[d] = std::max(1, static_cast<int>(cells / total));
      total *= along_[d];
    }
  }
  lower_ = lo;
  Point count;
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    count[d] = along_[d];
    total *= static_cast<std::size_t>(along_[d]);
  }
  bucket_size_ = extent.cwiseQuotient(count);

  std::vector<std::vector<int>> buckets(total);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const auto x = mesh.corners(c);
    Point clo = x[0], chi = clo;
    for (const auto& corner : x) {
      clo = clo.cwiseMin(corner);
      chi = chi.cwiseMax(corner);
    }
    box_lower_.push_back(clo);
    box_upper_.push_back(chi);
    if (const auto map = affine_map(x, (chi - clo).maxCoeff()))
      affine_.push_back(Affine{map->first, map->second});
    else
      affine_.push_back(Affine{Point::Constant(std::numeric_limits<double>::quiet_NaN()),
                               Jacobian::Constant(std::numeric_limits<double>::quiet_NaN())});
    std::array<int, Dim> first, last;
    for (int d = 0; d < Dim; ++d) {
      first[d] = bucket_index(clo, d);
      last[d] = bucket_index(chi, d);
    }
    if constexpr (Dim == 2) {
      for (int j = first[1]; j <= last[1]; ++j)
        for (int i = first[0]; i <= last[0]; ++i)
          buckets[static_cast<std::size_t>(j) * along_[0] + i].push_back(static_cast<int>(c));
    } else {
      for (int k = first[2]; k <= last[2]; ++k)
        for (int j = first[1]; j <= last[1]; ++j)
          for (int i = first[0]; i <= last[0]; ++i)
            buckets[(static_cast<std::size_t>(k) * along_[1] + j) * along_[0] + i].push_back(static_cast<int>(c));
    }
  }
  bucket_start_.push_back(0);
  for (const auto& b : buckets) {
    bucket_cells_.insert(bucket_cells_.end(), b.begin(), b.end());
    bucket_start_.push_back(static_cast<int>(bucket_cells_.size()));
  }
}

template <int Dim>
int CellLocatorOf<Dim>::bucket_index(const Point& p, int axis) const {
  return std::clamp(static_cast<int>((p[axis] - lower_[axis]) / bucket_size_[axis]), 0, along_[axis] - 1);
}

template <int Dim>
auto CellLocatorOf<Dim>::reference(std::size_t c, const Point& point) const -> std::optional<Point> {
  if (!affine(c)) return q1::inverse_map(mesh_.corners(c), point);
  Point ref;
  const Affine& map = affine_[c];
  const auto centre = [&map](int e) { return map.centre[e]; };
  const auto inverse = [&map](int r, int e) { return map.inverse_jacobian(r, e); };
  if (!reference_in([&point](int e) { return point[e]; }, centre, inverse, [&ref](int r, double v) { ref[r] = v; }))
    return std::nullopt;
  return ref;
}

template <int Dim>
auto CellLocatorOf<Dim>::hit(std::size_t c, const Point& reference) const -> Hit {
  return {static_cast<int>(c), reference, affine(c) ? &affine_[c].inverse_jacobian : nullptr};
}

template <int Dim>
auto CellLocatorOf<Dim>::locate(const Point& point, int* hint) const -> std::optional<Hit> {
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < mesh_.num_cells())
    if (const auto ref = reference(static_cast<std::size_t>(*hint), point))
      return hit(static_cast<std::size_t>(*hint), *ref);
  // Not-a-number coordinates (a particle gone wrong, which its solver
  // reports) lie nowhere, and would index no bucket.
  if (!point.allFinite()) return std::nullopt;
  const Point rel = (point - lower_).cwiseQuotient(bucket_size_);
  const double tol = 1e-9;
  std::size_t b = 0;
  for (int d = Dim - 1; d >= 0; --d) {
    if (rel[d] < -tol || rel[d] > along_[d] + tol) return std::nullopt;
    b = b * static_cast<std::size_t>(along_[d]) + static_cast<std::size_t>(std::clamp(static_cast<int>(rel[d]), 0, along_[d] - 1));
  }
  const Point slack = Point::Constant(tol).cwiseProduct(bucket_size_);
  for (int k = bucket_start_[b]; k < bucket_start_[b + 1]; ++k) {
    const int cell = bucket_cells_[k];
    const auto c = static_cast<std::size_t>(cell);
    if ((point.array() < (box_lower_[c] - slack).array()).any() ||
        (point.array() > (box_upper_[c] + slack).array()).any())
      continue;
    if (const auto ref = reference(c, point)) {
      if (hint) *hint = cell;
      return hit(c, *ref);
    }
  }
  return std::nullopt;
}

template class CellLocatorOf<2>;
template class CellLocatorOf<3>;

}  // namespace outburst::seepage
