#pragma once
// Finds the cell holding a point, for reading the pressure at arbitrary places
// (particle positions in the coupled runs). A uniform bucket grid over the cells'
// bounding boxes makes a query O(1) on any mesh; the exact test is the inverse
// isoparametric map of the few candidate cells.

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "seepage_fe/mesh.hpp"

namespace outburst::seepage {

template <int Dim>
class CellLocatorOf {
 public:
  using Point = typename MeshOf<Dim>::Point;
  using Jacobian = Eigen::Matrix<double, Dim, Dim>;

  explicit CellLocatorOf(const MeshOf<Dim>& mesh);

  struct Hit {
    int cell;
    Point reference;  // coordinates in [-1, 1]^Dim
    // d(reference) / d(x) of a parallelogram (parallelepiped), constant over
    // the cell; null for other cells. Samplers take gradients from it without
    // a Jacobian.
    const Jacobian* inverse_jacobian = nullptr;
  };
  // `hint`, if given, is a cell to try first (where the point was last time);
  // it is updated to the cell found. Any hint is safe: a wrong one costs one test.
  std::optional<Hit> locate(const Point& point, int* hint = nullptr) const;
  // Buckets of the search grid: at most one per cell.
  std::size_t buckets() const { return bucket_start_.size() - 1; }

  // A parallelogram's map to the reference square is affine: its reference
  // coordinates are inverse_jacobian (x - centre), with no Newton iteration.
  // Coupled runs locate every particle every step, and most meshes are of
  // such cells (structured and transfinite ones all are).
  struct Affine {
    Point centre;
    Jacobian inverse_jacobian;
  };
  // Each cell's affine map; a cell of another shape holds NaN, which no
  // reference coordinates taken from it pass as inside.
  const std::vector<Affine>& affine_maps() const { return affine_; }
  // The reference coordinates of the point x(e) in an affine cell, centre(e)
  // and inverse(r, c) its map's entries, each clamped into [-1, 1] and handed
  // to ref(r, value); whether x lies in the cell to 1e-9 of its size
  // (q1::inverse_map's acceptance: a point on an edge two cells share is
  // found). Written out for one point, so that SIMD lanes over points run
  // the same operations (tests check their numbers against a point's alone,
  // to the bit).
  template <class X, class Centre, class Inverse, class Ref>
  [[gnu::always_inline]] static bool reference_in(const X& x, const Centre& centre, const Inverse& inverse,
                                                  const Ref& ref) {
    double d[Dim];
#pragma GCC unroll 3
    for (int e = 0; e < Dim; ++e) d[e] = x(e) - centre(e);
    bool inside = true;
#pragma GCC unroll 3
    for (int r = 0; r < Dim; ++r) {
      double sum = inverse(r, 0) * d[0];
#pragma GCC unroll 2
      for (int e = 1; e < Dim; ++e) sum += inverse(r, e) * d[e];
      inside &= std::abs(sum) <= 1 + 1e-9;
      ref(r, std::min(std::max(sum, -1.0), 1.0));
    }
    return inside;
  }

 private:
  const MeshOf<Dim>& mesh_;
  Point lower_, bucket_size_;
  std::array<int, Dim> along_{};   // buckets along each axis
  std::vector<int> bucket_start_;  // CSR layout: cells of bucket b are
  std::vector<int> bucket_cells_;  // bucket_cells_[bucket_start_[b] .. bucket_start_[b+1])
  std::vector<Point> box_lower_, box_upper_;  // bounding box per cell
  std::vector<Affine> affine_;
  bool affine(std::size_t c) const { return !std::isnan(affine_[c].centre[0]); }
  // The reference coordinates of point in cell c, or nullopt outside it.
  std::optional<Point> reference(std::size_t c, const Point& point) const;
  Hit hit(std::size_t c, const Point& reference) const;
  int bucket_index(const Point& p, int axis) const;
};

using CellLocator = CellLocatorOf<2>;

}  // namespace outburst::seepage
