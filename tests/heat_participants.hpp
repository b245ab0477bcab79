#pragma once
// The textbook partitioned problem, as preCICE's heat tutorial poses it: the
// heat equation u_t = laplace(u) + f on [0, 2] x [0, 1], cut at x = 1 into a
// Dirichlet half (left: takes u on the cut, gives the flux du/dx there) and a
// Neumann half (right: takes the flux, gives u on the cut). The manufactured
// solution u = 1 + x^2 + 3 y^2 + 1.2 t (f = 1.2 - 8) is quadratic in space and
// linear in time, which the five-point Laplacian, second-order boundary
// differences and backward Euler reproduce exactly: the coupled answer must
// match it to round-off. Finite differences on purpose: the test is of the
// coupling, not of a discretisation.
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include "coupler/coupling.hpp"

namespace outburst::testing {

inline double heat_exact(double x, double y, double t) { return 1 + x * x + 3 * y * y + 1.2 * t; }

class HeatHalf final : public coupling::Participant {
 public:
  enum class Side { dirichlet, neumann };
  // n x n cells of size 1/n on [x0, x0 + 1] x [0, 1]; one backward-Euler step per window.
  HeatHalf(Side side, int n, double dt) : side_(side), n_(n), h_(1.0 / n), dt_(dt) {
    x0_ = side == Side::dirichlet ? 0.0 : 1.0;
    cut_column_ = side == Side::dirichlet ? n : 0;
    u_.resize((n + 1) * (n + 1));
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) u_[index(i, j)] = heat_exact(x(i), y(j), 0);
    cut_.resize(n + 1);
    for (int j = 0; j <= n; ++j) cut_[j] = side == Side::dirichlet ? heat_exact(1, y(j), 0) : 0.0;
    build_matrix();
  }

  std::string name() const override { return side_ == Side::dirichlet ? "dirichlet" : "neumann"; }
  void write(const std::string&, const Eigen::VectorXd& values) override { cut_ = values; }
  Eigen::VectorXd read(const std::string&) const override {
    Eigen::VectorXd out(n_ + 1);
    for (int j = 0; j <= n_; ++j)
      out[j] = side_ == Side::dirichlet
                   ? (3 * u_[index(n_, j)] - 4 * u_[index(n_ - 1, j)] + u_[index(n_ - 2, j)]) / (2 * h_)
                   : u_[index(0, j)];
    return out;
  }
  void save() override { saved_ = {u_, t_}; }
  void restore() override { std::tie(u_, t_) = saved_; }

  void advance(double window) override {
    if (std::abs(window - dt_) > 1e-12) throw std::invalid_argument("one step per window");
    const double t = t_ + dt_;
    Eigen::VectorXd b = u_ / dt_;
    b.array() += 1.2 - 8.0;
    for (int j = 0; j <= n_; ++j)
      for (int i = 0; i <= n_; ++i) {
        const int k = index(i, j);
        const bool outer = j == 0 || j == n_ || (i == 0 && side_ == Side::dirichlet) ||
                           (i == n_ && side_ == Side::neumann);
        if (outer)
          b[k] = heat_exact(x(i), y(j), t);
        else if (i == cut_column_ && side_ == Side::dirichlet)
          b[k] = cut_[j];
        else if (i == cut_column_)  // ghost u(-1) = u(1) - 2 h q eliminated
          b[k] += -2 * h_ * cut_[j] / (h_ * h_);
      }
    u_ = solver_.solve(b);
    t_ = t;
  }

  double max_error() const {
    double e = 0;
    for (int j = 0; j <= n_; ++j)
      for (int i = 0; i <= n_; ++i) e = std::max(e, std::abs(u_[index(i, j)] - heat_exact(x(i), y(j), t_)));
    return e;
  }

 private:
  int index(int i, int j) const { return j * (n_ + 1) + i; }
  double x(int i) const { return x0_ + i * h_; }
  double y(int j) const { return j * h_; }

  void build_matrix() {
    std::vector<Eigen::Triplet<double>> t;
    const double c = 1 / (h_ * h_);
    for (int j = 0; j <= n_; ++j)
      for (int i = 0; i <= n_; ++i) {
        const int k = index(i, j);
        const bool fixed = j == 0 || j == n_ || (i == 0 && side_ == Side::dirichlet) ||
                           (i == n_ && side_ == Side::neumann) || (i == cut_column_ && side_ == Side::dirichlet);
        if (fixed) {
          t.emplace_back(k, k, 1.0);
          continue;
        }
        t.emplace_back(k, k, 1 / dt_ + 4 * c);
        t.emplace_back(k, index(i, j - 1), -c);
        t.emplace_back(k, index(i, j + 1), -c);
        if (i == cut_column_) {  // Neumann cut, i = 0: the ghost mirrors u(1)
          t.emplace_back(k, index(1, j), -2 * c);
        } else {
          t.emplace_back(k, index(i - 1, j), -c);
          t.emplace_back(k, index(i + 1, j), -c);
        }
      }
    Eigen::SparseMatrix<double> a((n_ + 1) * (n_ + 1), (n_ + 1) * (n_ + 1));
    a.setFromTriplets(t.begin(), t.end());
    solver_.compute(a);
  }

  Side side_;
  int n_;
  double h_, dt_, x0_ = 0, t_ = 0;
  int cut_column_;
  Eigen::VectorXd u_, cut_;
  std::pair<Eigen::VectorXd, double> saved_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> solver_;
};

}  // namespace outburst::testing
