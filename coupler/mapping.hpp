#pragma once
// Data mapping between the seepage mesh (fixed Q1 quadrilaterals) and the
// material points (moving, each with a volume):
//
//   mesh -> points: a nodal field and its gradient at any point, by the Q1
//     shape functions of the cell holding it (consistent: a linear field is
//     reproduced exactly, gradient included).
//   points -> mesh: per cell, the solid volume fraction (sum of the volumes of
//     the points in it over the cell's area) and volume-weighted averages
//     (conservative: sum over cells of average x solid volume = sum over points
//     of value x volume).
//
// A point outside the mesh maps to nothing (no gas force, no share in a cell).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "seepage_fe/cell_locator.hpp"
#include "seepage_fe/mesh.hpp"
#include "seepage_fe/q1.hpp"

namespace outburst::coupling {

class MeshMapping {
 public:
  explicit MeshMapping(seepage::Mesh mesh);
  MeshMapping(const MeshMapping&) = delete;  // the locator refers into mesh_
  MeshMapping& operator=(const MeshMapping&) = delete;

  const seepage::Mesh& mesh() const { return mesh_; }
  const std::vector<double>& cell_area() const { return area_; }

  using Sample = seepage::q1::Sample;
  // Nodal field and its gradient at x; nullopt outside the mesh. `hint`: the
  // cell to try first, updated (see CellLocator::locate).
  std::optional<Sample> sample(const Eigen::VectorXd& nodal, const Eigen::Vector2d& x, int* hint = nullptr) const;
  // The cell holding x, or -1.
  int cell_of(const Eigen::Vector2d& x) const;

  // Volume-weighted cell averages of `components` values per point
  // (values[p * components + k]); cells without points get 0. Also returns the
  // solid volume fraction per cell.
  struct Averages {
    std::vector<double> fraction;  // solid volume / cell area
    std::vector<double> mean;      // per cell, `components` values
  };
  Averages average(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& volume,
                   const std::vector<double>& values, int components) const;

 private:
  seepage::Mesh mesh_;
  seepage::CellLocator locator_;
  std::vector<double> area_;
};

}  // namespace outburst::coupling
