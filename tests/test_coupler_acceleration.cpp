// The accelerations on fixed-point problems with known behaviour, and the
// coupling scheme's protocol with participants that record what happens.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>
#include <vector>

#include "coupler/accelerations/aitken.hpp"
#include "coupler/accelerations/constant.hpp"
#include "coupler/accelerations/iqn_ils.hpp"
#include "coupler/coupling.hpp"

using namespace outburst::coupling;

namespace {

// Iterate y = H(y) for the affine map H(y) = A y + b; returns the iterations
// to |H(y) - y| <= tol |H(y)|.
int iterate(Acceleration& acc, const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
            const std::vector<FieldSlice>& fields, int max = 200) {
  acc.start_window(fields);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
  for (int k = 1; k <= max; ++k) {
    const Eigen::VectorXd x = a * y + b;
    if ((x - y).norm() <= 1e-10 * x.norm()) return k;
    y = acc.next(y, x);
  }
  return max + 1;
}

std::vector<FieldSlice> one_field(Eigen::Index n) { return {{"y", 0, static_cast<std::size_t>(n)}}; }

}  // namespace

TEST_CASE("Aitken solves a scalar linear fixed point in three iterations", "[coupler][acceleration]") {
  // One relaxed step, then the secant through two residuals is exact.
  Eigen::MatrixXd a(1, 1);
  a << -3.0;  // plain iteration diverges
  Eigen::VectorXd b(1);
  b << 2.0;
  Aitken aitken(0.5);
  CHECK(iterate(aitken, a, b, one_field(1)) <= 3);
  ConstantRelaxation plain(1.0);
  CHECK(iterate(plain, a, b, one_field(1)) > 200);
}

TEST_CASE("IQN-ILS solves an n-dimensional linear fixed point in at most n + 2 iterations",
          "[coupler][acceleration]") {
  // With exact arithmetic the secant columns span the residual space after n
  // differences: a quasi-Newton method is then exact on an affine map.
  const int n = 6;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    a(i, i) = -1.5 + 0.4 * i;  // eigenvalues beyond 1 in modulus: plain iteration diverges
    if (i + 1 < n) a(i, i + 1) = 0.3;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1, 2);
  AccelerationSettings s;
  s.filter = 1e-8;
  s.reuse_windows = 0;
  IqnIls iqn(s);
  const int iterations = iterate(iqn, a, b, one_field(n));
  std::printf("\nIQN-ILS on a %d-dimensional affine map: %d iterations\n", n, iterations);
  CHECK(iterations <= n + 2);
}

TEST_CASE("IQN-ILS reuse of past windows cuts the iterations of a repeated problem", "[coupler][acceleration]") {
  const int n = 8;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) a(i, i) = -0.9 + 0.2 * i;
  Eigen::VectorXd b = Eigen::VectorXd::Ones(n);
  AccelerationSettings s;
  s.reuse_windows = 4;
  IqnIls iqn(s);
  const int first = iterate(iqn, a, b, one_field(n));
  iqn.end_window(true);
  b *= 1.1;  // the next window: same operator, new data
  const int second = iterate(iqn, a, b, one_field(n));
  std::printf("\nIQN-ILS with reuse: %d iterations in the first window, %d in the next\n", first, second);
  CHECK(second < first);
}

TEST_CASE("the per-field preconditioner makes IQN-ILS blind to a field's units", "[coupler][acceleration]") {
  // Two coupled fields; expressing the second in units a million times smaller
  // (a stress in Pa instead of MPa) must not change the iterations.
  const int n = 4;
  Eigen::MatrixXd a(2 * n, 2 * n);
  a.setZero();
  for (int i = 0; i < n; ++i) {
    a(i, n + i) = 0.8;
    a(n + i, i) = -1.1;
    a(i, i) = 0.1 * i;
  }
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(2 * n, 1, 3);
  const std::vector<FieldSlice> fields{{"first", 0, n}, {"second", n, n}};
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(2 * n);
  scale.tail(n).setConstant(1e6);
  const Eigen::MatrixXd scaled = scale.asDiagonal() * a * scale.cwiseInverse().asDiagonal();
  AccelerationSettings s;
  s.reuse_windows = 0;
  IqnIls plain(s), in_other_units(s);
  const int k1 = iterate(plain, a, b, fields);
  const int k2 = iterate(in_other_units, scaled, scale.cwiseProduct(b), fields);
  std::printf("\nIQN-ILS: %d iterations in consistent units, %d with one field scaled by 1e6\n", k1, k2);
  CHECK(k1 == k2);
}

namespace {

// A participant whose single output is H(input) = gain * input + offset, and
// that counts its calls.
class Mock final : public Participant {
 public:
  Mock(std::string name, double gain, double offset) : name_(std::move(name)), gain_(gain), offset_(offset) {}
  std::string name() const override { return name_; }
  void write(const std::string&, const Eigen::VectorXd& v) override { input_ = v; }
  Eigen::VectorXd read(const std::string&) const override { return output_; }
  void advance(double) override {
    ++advances;
    output_ = gain_ * input_ + Eigen::VectorXd::Constant(input_.size(), offset_);
  }
  void save() override { ++saves; saved_ = output_; }
  void restore() override { ++restores; output_ = saved_; }
  int advances = 0, saves = 0, restores = 0;
  Eigen::VectorXd input_ = Eigen::VectorXd::Zero(3), output_ = Eigen::VectorXd::Zero(3), saved_;

 private:
  std::string name_;
  double gain_, offset_;
};

}  // namespace

TEST_CASE("coupling schemes: one-way and explicit pass once, implicit repeats to convergence", "[coupler][scheme]") {
  SchemeSettings s;
  s.to_second = {"a"};
  s.to_first = {{"b", 1e-10, 0}};
  SECTION("one-way sends nothing back") {
    Mock first("first", 1, 1), second("second", 2, 0);
    s.kind = SchemeSettings::Kind::one_way;
    Coupling c(first, second, s);
    c.advance(1);
    c.advance(1);
    CHECK(first.advances == 2);
    CHECK(second.advances == 2);
    CHECK(first.input_.isZero());
    CHECK(first.saves == 0);
  }
  SECTION("explicit sends second's data to first's next window") {
    Mock first("first", 1, 1), second("second", 2, 0);
    s.kind = SchemeSettings::Kind::explicit_staggered;
    Coupling c(first, second, s);
    c.advance(1);  // first: 0 + 1 = 1; second: 2
    c.advance(1);  // first: 2 + 1 = 3; second: 6
    CHECK(second.output_[0] == 6);
    CHECK(c.records().back().iterations == 1);
  }
  SECTION("implicit converges to the fixed point y = -0.4 (y + 1)") {
    // first: x = y + 1; second: y = -0.4 x; fixed point y = -0.4 / 1.4.
    Mock first("first", 1, 1), second("second", -0.4, 0);
    s.kind = SchemeSettings::Kind::implicit;
    s.acceleration.kind = "aitken";
    Coupling c(first, second, s);
    const auto& r = c.advance(1);
    CHECK(r.converged);
    CHECK(second.output_[0] == Approx(-0.4 / 1.4).epsilon(1e-9));
    CHECK(first.restores == r.iterations - 1);
  }
}

TEST_CASE("coupling: a non-finite field stops the window naming it, and a diverged window is never converged",
          "[coupler][scheme]") {
  SchemeSettings s;
  s.kind = SchemeSettings::Kind::implicit;
  s.to_second = {"a"};
  s.to_first = {{"stress", 1e-10, 0}};
  s.acceleration.kind = "constant";
  s.acceleration.relaxation = 1.0;
  s.max_iterations = 5;
  SECTION("NaN") {
    Mock first("seepage", 1, std::numeric_limits<double>::quiet_NaN()), second("solid", 1, 0);
    Coupling c(first, second, s);
    CHECK_THROWS_WITH(c.advance(1), Catch::Contains("field 'a' from seepage") && Catch::Contains("non-finite"));
  }
  SECTION("divergence stops, or is recorded") {
    Mock first("seepage", 1, 1), second("solid", -2, 0);  // |gain| 2: plain iteration diverges
    Coupling stop(first, second, s);
    CHECK_THROWS_WITH(stop.advance(1), Catch::Contains("did not converge in 5 iterations") &&
                                           Catch::Contains("'stress'"));
    s.stop_on_divergence = false;
    Mock first2("seepage", 1, 1), second2("solid", -2, 0);
    Coupling go_on(first2, second2, s);
    const auto& r = go_on.advance(1);
    CHECK_FALSE(r.converged);
    CHECK(r.iterations == 5);
  }
}

TEST_CASE("a scene names a registered acceleration, and an unknown name is refused with it", "[coupler][acceleration]") {
  std::vector<std::string_view> names;
  for (const auto& model : acceleration_models()) names.push_back(model.name);
  for (const char* name : {"aitken", "constant", "iqn_ils"}) {
    CHECK(std::find(names.begin(), names.end(), name) != names.end());
    AccelerationSettings s;
    s.kind = name;
    CHECK(make_acceleration(s) != nullptr);
  }
  CHECK(std::is_sorted(names.begin(), names.end()));
  AccelerationSettings unknown;
  unknown.kind = "anderson";
  CHECK_THROWS_WITH(make_acceleration(unknown), Catch::Contains("anderson"));
}
