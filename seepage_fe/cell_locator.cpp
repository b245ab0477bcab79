#include "seepage_fe/cell_locator.hpp"

#include <algorithm>
#include <cmath>

#include "seepage_fe/q1.hpp"

namespace outburst::seepage {

CellLocator::CellLocator(const Mesh& mesh) : mesh_(mesh) {
  Eigen::Vector2d lo = mesh.nodes.front(), hi = mesh.nodes.front();
  for (const auto& p : mesh.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // About one cell per bucket on average, in buckets matching the domain's
  // shape; never more buckets than cells, however thin the domain (a mesh
  // 3e-22 m high asked for 1.6e8 buckets).
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-12);
  const double cells = static_cast<double>(mesh.num_cells());
  const double aspect = extent.x() / extent.y();
  nx_ = static_cast<int>(std::clamp(std::sqrt(cells * aspect), 1.0, cells));
  ny_ = std::max(1, static_cast<int>(cells / nx_));
  lower_ = lo;
  bucket_size_ = extent.cwiseQuotient(Eigen::Vector2d(nx_, ny_));

  std::vector<std::vector<int>> buckets(static_cast<std::size_t>(nx_) * ny_);
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    Eigen::Vector2d clo = mesh.nodes[mesh.cells[c][0]], chi = clo;
    for (int k = 1; k < 4; ++k) {
      clo = clo.cwiseMin(mesh.nodes[mesh.cells[c][k]]);
      chi = chi.cwiseMax(mesh.nodes[mesh.cells[c][k]]);
    }
    box_lower_.push_back(clo);
    box_upper_.push_back(chi);
    const q1::Corners x = mesh.corners(c);
    // x0 - x1 + x2 - x3 is the bilinear term's coefficient (times 4): zero,
    // to roundoff, for a parallelogram.
    if ((x[0] - x[1] + x[2] - x[3]).lpNorm<Eigen::Infinity>() <= 1e-12 * (chi - clo).maxCoeff()) {
      Eigen::Matrix2d jacobian;  // d(x, y) / d(xi, eta), constant
      jacobian << 0.5 * (x[1] - x[0]), 0.5 * (x[3] - x[0]);
      affine_.push_back(Affine{0.25 * (x[0] + x[1] + x[2] + x[3]), jacobian.inverse()});
    } else {
      affine_.emplace_back();
    }
    const auto index = [&](const Eigen::Vector2d& p, int axis, int n) {
      return std::clamp(static_cast<int>((p[axis] - lower_[axis]) / bucket_size_[axis]), 0, n - 1);
    };
    for (int j = index(clo, 1, ny_); j <= index(chi, 1, ny_); ++j)
      for (int i = index(clo, 0, nx_); i <= index(chi, 0, nx_); ++i)
        buckets[static_cast<std::size_t>(j) * nx_ + i].push_back(static_cast<int>(c));
  }
  bucket_start_.push_back(0);
  for (const auto& b : buckets) {
    bucket_cells_.insert(bucket_cells_.end(), b.begin(), b.end());
    bucket_start_.push_back(static_cast<int>(bucket_cells_.size()));
  }
}

std::optional<Eigen::Vector2d> CellLocator::reference(std::size_t c, const Eigen::Vector2d& point) const {
  if (!affine_[c]) return q1::inverse_map(mesh_.corners(c), point);
  // The acceptance of q1::inverse_map: a point on a shared edge is found.
  const Eigen::Vector2d ref = affine_[c]->inverse_jacobian * (point - affine_[c]->centre);
  if (ref.lpNorm<Eigen::Infinity>() > 1 + 1e-9) return std::nullopt;
  return ref.cwiseMax(-1.0).cwiseMin(1.0);
}

CellLocator::Hit CellLocator::hit(std::size_t c, const Eigen::Vector2d& reference) const {
  return {static_cast<int>(c), reference, affine_[c] ? &affine_[c]->inverse_jacobian : nullptr};
}

std::optional<CellLocator::Hit> CellLocator::locate(const Eigen::Vector2d& point, int* hint) const {
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < mesh_.num_cells())
    if (const auto ref = reference(static_cast<std::size_t>(*hint), point))
      return hit(static_cast<std::size_t>(*hint), *ref);
  const Eigen::Vector2d rel = (point - lower_).cwiseQuotient(bucket_size_);
  const double tol = 1e-9;
  if (rel.x() < -tol || rel.y() < -tol || rel.x() > nx_ + tol || rel.y() > ny_ + tol)
    return std::nullopt;
  const int i = std::clamp(static_cast<int>(rel.x()), 0, nx_ - 1);
  const int j = std::clamp(static_cast<int>(rel.y()), 0, ny_ - 1);
  const int b = j * nx_ + i;
  const Eigen::Vector2d slack = Eigen::Vector2d::Constant(tol).cwiseProduct(bucket_size_);
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

}  // namespace outburst::seepage
