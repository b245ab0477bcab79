// The C++ tests' analytic solutions (poroelastic_solutions.hpp) at points a
// caller names, so that the Python measures' own series (cases/terzaghi,
// cases/mandel) can be checked against them (tests/python/test_analytic.py):
// two implementations of each solution, kept from drifting apart.
//
//   analytic-samples terzaghi H q E nu storage alpha mobility z t
//                                              -> p(z, t)
//   analytic-samples mandel a b F E nu storage alpha mobility x t
//                                              -> p(x, t) and the plate's settlement at t
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "poroelastic_solutions.hpp"

namespace {

std::vector<double> numbers(int argc, char** argv, int count) {
  if (argc != count + 2) {
    std::fprintf(stderr, "%s %s: expected %d numbers\n", argv[0], argv[1], count);
    std::exit(2);
  }
  std::vector<double> v;
  for (int i = 2; i < argc; ++i) {
    char* end = nullptr;
    v.push_back(std::strtod(argv[i], &end));
    if (end == argv[i] || *end != '\0') {
      std::fprintf(stderr, "%s %s: \"%s\" is not a number\n", argv[0], argv[1], argv[i]);
      std::exit(2);
    }
  }
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace outburst::testing;
  const std::string which = argc > 1 ? argv[1] : "";
  if (which == "terzaghi") {
    const auto v = numbers(argc, argv, 9);
    std::printf("%.17g\n", Terzaghi::of_column(v[0], v[1], v[2], v[3], v[4], v[5], v[6]).pressure(v[7], v[8]));
  } else if (which == "mandel") {
    const auto v = numbers(argc, argv, 10);
    const Mandel m(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]);
    std::printf("%.17g %.17g\n", m.pressure(v[8], v[9]), m.settlement(v[9]));
  } else {
    std::fprintf(stderr, "usage: analytic-samples terzaghi|mandel NUMBERS...\n");
    return 2;
  }
  return 0;
}
