#pragma once
// Data mapping between the seepage mesh (fixed Q1 quadrilaterals, hexahedra in
// 3D) and the material points (moving, each with a volume):
//
//   mesh -> points: a nodal field and its gradient at any point, by the Q1
//     shape functions of the cell holding it (consistent: a linear field is
//     reproduced exactly, gradient included).
//   points -> mesh: per cell, the solid volume fraction (sum of the volumes of
//     the points in it over the cell's area) and volume-weighted averages
//     (conservative: sum over cells of average x solid volume = sum over points
//     of value x volume). In 2D areas and volumes are per metre of depth.
//
// A point outside the mesh maps to nothing (no gas force, no share in a cell).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "seepage_fe/sampling.hpp"

namespace outburst::coupling {

template <int Dim>
class MeshMapping {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;
  // Reads the mesh through the seepage's sampler, which must outlive it.
  explicit MeshMapping(const seepage::SamplerOf<Dim>& sampler) : sampler_(sampler) {}

  const seepage::MeshOf<Dim>& mesh() const { return sampler_.mesh(); }
  // Each cell's area (volume in 3D).
  const std::vector<double>& cell_area() const { return sampler_.cell_area(); }

  using Sample = typename seepage::SamplerOf<Dim>::Value;
  // Nodal field and its gradient at x; nullopt outside the mesh. `hint`: the
  // cell to try first, updated (see seepage::Sampler::sample).
  std::optional<Sample> sample(const Eigen::VectorXd& nodal, const Point& x, int* hint = nullptr) const {
    return sampler_.sample(nodal, x, hint);
  }
  // The same at up to batch_lanes points at once (seepage::Sampler's batch).
  static constexpr int batch_lanes = seepage::SamplerOf<Dim>::batch_lanes;
  using Batch = typename seepage::SamplerOf<Dim>::Batch;
  void sample(const Eigen::VectorXd& nodal, const double* x, int count, int* hint, Batch& out) const {
    sampler_.sample(nodal, x, count, hint, out);
  }
  // The cell holding x, or -1.
  int cell_of(const Point& x) const { return sampler_.cell_of(x); }

  // Volume-weighted cell averages of `components` values per point
  // (values[p * components + k]); cells without points get 0. Also returns the
  // solid volume fraction per cell.
  struct Averages {
    std::vector<double> fraction;  // solid volume / cell area
    std::vector<double> mean;      // per cell, `components` values
  };
  Averages average(const std::vector<Point>& points, const std::vector<double>& volume,
                   const std::vector<double>& values, int components) const;

 private:
  const seepage::SamplerOf<Dim>& sampler_;
};

}  // namespace outburst::coupling
