#include <catch2/catch.hpp>

#include "common/units.hpp"

namespace u = outburst::units;
using u::Dimension;
using u::Quantity;
using u::parse_quantity;

TEST_CASE("quantities convert to SI and carry their dimension", "[units]") {
  struct Row {
    const char* text;
    double si;
    Dimension dimension;
  };
  const Row rows[] = {
      {"3 MPa", 3e6, u::pressure},
      {"1.5e6 Pa", 1.5e6, u::pressure},
      {"2 h", 7200, u::time},
      {"10 d", 864000, u::time},
      {"30 deg", 0.52359877559829887, u::angle},
      {"1600 kg/m3", 1600, u::density},
      {"9.81 m/s2", 9.81, u::acceleration},
      {"9.81 m/s^2", 9.81, u::acceleration},
      {"1e-9 1/Pa", 1e-9, u::inverse_pressure},
      {"0.1 m2/(MPa2 d)", 0.1 / (1e12 * 86400), u::gas_conductivity},
      {"0.1 m^2/(MPa^2*d)", 0.1 / (1e12 * 86400), u::gas_conductivity},
      {"2 MPa^-0.5", 2e-3, u::gas_content_per_volume},
      {"1.25 m3/(t MPa^0.5)", 1.25e-3 / 1e3, u::gas_content_per_mass},
      {"1e-3 Pa s", 1e-3, u::viscosity},
      {"1e-3 Pa.s", 1e-3, u::viscosity},
      {"0.5", 0.5, u::dimensionless},
      {"2 MPa^-5e-1", 2e-3, u::gas_content_per_volume},
  };
  for (const auto& row : rows) {
    INFO(row.text);
    const Quantity q = parse_quantity(row.text);
    CHECK(q.si == Approx(row.si).epsilon(1e-12));
    CHECK(q.dimension == row.dimension);
  }
}

TEST_CASE("malformed quantities are rejected with the reason", "[units]") {
  const std::pair<const char*, const char*> rows[] = {
      {"MPa", "does not start with a number"},
      {"3 Mpa", "unknown unit 'Mpa'"},
      {"3 m/(s", "missing ')'"},
      {"3 m^", "expected an exponent"},
      {"3 m #", "unexpected '#'"},
      // Numbers beyond a double: said so (before: "must be > 0", "unknown unit 'e'").
      {"1e308 d", "\"1e308 d\" overflows: in SI it exceeds the largest number"},
      {"1e-320 MPa^-40", "underflows"},
      {"1e400 Pa", "is beyond the range of numbers"},
      {"3 MPa^1e400", "1e400 is out of range"},
      {"3 MPa^400", "the power ^400 takes the unit beyond the range of numbers"},
      // Named as what they are (before: "overflows").
      {"NaN d", "\"NaN d\" starts with NaN, which is not a value"},
      {"nan s", "starts with NaN"},
      {"-inf Pa", "starts with an infinite number"},
      {"infinity m", "starts with an infinite number"},
  };
  for (const auto& [text, message] : rows) {
    INFO(text);
    CHECK_THROWS_WITH(parse_quantity(text), Catch::Contains(message));
  }
}

TEST_CASE("dimensions are named in messages", "[units]") {
  CHECK(u::describe(u::pressure) == "pressure");
  CHECK(u::describe(u::time) == "time");
  CHECK(u::describe(Dimension{2, 0, -3, 0}) == "m^2 s^-3");
}

TEST_CASE("parentheses nested deeper than 32 levels are refused, however deep", "[units]") {
  // Before: 50,000 of them overflowed the stack in the parser's recursion.
  const auto nested = [](int n) { return "30 " + std::string(n, '(') + "d" + std::string(n, ')'); };
  CHECK(parse_quantity(nested(32)).si == 30 * 86400.0);
  CHECK_THROWS_WITH(parse_quantity(nested(33)), Catch::Contains("parentheses nested deeper than 32 levels"));
  CHECK_THROWS_WITH(parse_quantity(nested(50000)), Catch::Contains("parentheses nested deeper than 32 levels"));
  CHECK_THROWS_WITH(parse_quantity("3 " + std::string(1000000, '(')), Catch::Contains("nested deeper"));
}
