#pragma once
// A seepage mesh's nodal fields read at arbitrary points (particle positions,
// probes), and the cell holding a point: the face the seepage shows other
// parts (the coupler), so that they need neither its cell search nor its
// element.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "seepage_fe/cell_locator.hpp"
#include "seepage_fe/mesh.hpp"

namespace outburst::seepage {

template <int Dim>
class SamplerOf {
 public:
  using Point = typename MeshOf<Dim>::Point;

  // Refers to `mesh`, which must outlive it and stay put.
  explicit SamplerOf(const MeshOf<Dim>& mesh);
  SamplerOf(const SamplerOf&) = delete;
  SamplerOf& operator=(const SamplerOf&) = delete;

  const MeshOf<Dim>& mesh() const { return mesh_; }
  // The area (3D: volume) of each cell [m2, m3].
  const std::vector<double>& cell_area() const { return area_; }

  struct Value {
    double value;
    Point gradient;
  };
  // A nodal field (indexed by node) and its gradient at x, by the Q1 shape
  // functions of the cell holding it; nullopt outside the mesh. `hint`: a
  // cell to try first, updated to the cell found (any hint is safe; a wrong
  // one costs one test).
  std::optional<Value> sample(const Eigen::VectorXd& nodal, const Point& x, int* hint = nullptr) const;

  // The same at `count` points at once, at most batch_lanes: point k's
  // coordinates are x[Dim k ..], its hint hint[k] (every point has one,
  // updated as above). SIMD lanes take the points still in their hinted
  // parallelogram (parallelepiped), the call above the others. The lanes run
  // the call's formula (CellLocator::reference_in, q1::sample_affine), and
  // tests check that each point gets its numbers to the bit. Coupled runs
  // read the pressure at every particle every MPM step: one point at a time,
  // that took a tenth of the run to rest's time.
  static constexpr int batch_lanes = 16;
  struct Batch {
    alignas(64) double value[batch_lanes];
    alignas(64) double gradient[Dim][batch_lanes];
    alignas(64) double found[batch_lanes];  // 1 inside the mesh, 0 outside (value and gradient 0)
    int by_lanes;  // points the lanes took (the others went one by one)
  };
  void sample(const Eigen::VectorXd& nodal, const double* x, int count, int* hint, Batch& out) const;
  // The cell holding x, or -1.
  int cell_of(const Point& x, int* hint = nullptr) const;

 private:
  const MeshOf<Dim>& mesh_;
  CellLocatorOf<Dim> locator_;
  std::vector<double> area_;
};

using Sampler = SamplerOf<2>;

}  // namespace outburst::seepage
