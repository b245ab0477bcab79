#pragma once
// Physical quantities at the scene-file boundary.
//
// Inside the code everything is SI (m, kg, s, Pa). A scene writes dimensional
// values as strings with their unit ("3 MPa", "0.1 m2/(MPa2 d)", "30 deg"); this
// module parses them, checks the dimension the key expects and converts to SI, so
// a value in the wrong unit is an error instead of a silent factor of 1e6.

#include <stdexcept>
#include <string>
#include <string_view>

namespace outburst::units {

// Exponents of the base dimensions. Exponents may be fractional (MPa^0.5 in the
// gas content coefficient). Angle is kept as its own dimension so that a friction
// angle written without "deg" or "rad" is caught.
struct Dimension {
  double length = 0, mass = 0, time = 0, angle = 0;

  bool operator==(const Dimension& other) const;
  Dimension operator*(const Dimension& other) const;
  Dimension operator/(const Dimension& other) const;
  Dimension pow(double exponent) const;
};

inline constexpr Dimension dimensionless{};
inline constexpr Dimension length{1, 0, 0, 0};
inline constexpr Dimension mass{0, 1, 0, 0};
inline constexpr Dimension time{0, 0, 1, 0};
inline constexpr Dimension angle{0, 0, 0, 1};
inline constexpr Dimension pressure{-1, 1, -2, 0};
inline constexpr Dimension velocity{1, 0, -1, 0};
inline constexpr Dimension acceleration{1, 0, -2, 0};
inline constexpr Dimension density{-3, 1, 0, 0};
inline constexpr Dimension inverse_pressure{1, -1, 2, 0};
inline constexpr Dimension area{2, 0, 0, 0};
inline constexpr Dimension viscosity{-1, 1, -1, 0};
inline constexpr Dimension rate{0, 0, -1, 0};  // 1/s
inline constexpr Dimension force{1, 1, -2, 0};             // N
inline constexpr Dimension force_per_length{0, 1, -2, 0};  // N/m: a 2D model's force per metre of depth
inline constexpr Dimension energy_per_area = force_per_length;  // J/m2 = N/m: a fracture energy
// lambda in q = -lambda grad(p^2): m^2 / (Pa^2 s)
inline constexpr Dimension gas_conductivity{4, -2, 3, 0};
// k / mu in q = -(k / mu) grad(p): m^2 / (Pa s)
inline constexpr Dimension mobility{3, -1, 1, 0};
// A in X = A sqrt(p), per unit volume of coal: Pa^-1/2
inline constexpr Dimension gas_content_per_volume{0.5, -0.5, 1, 0};
// A per unit mass of coal (m^3/(t MPa^0.5)): needs the coal density
inline constexpr Dimension gas_content_per_mass{3.5, -1.5, 1, 0};

// A readable name ("pressure") or the exponent formula ("m^2 kg^-1 s^3").
std::string describe(const Dimension& d);
// A unit of that dimension scenes write ("Pa", "deg"); empty when none of
// the known units has it alone.
std::string symbol(const Dimension& d);

struct Quantity {
  double si;  // value converted to SI
  Dimension dimension;
};

class UnitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parse "<number> <unit expression>". Unit expressions combine known units with
// products (space, '*' or '.'), quotients ('/'), parentheses and powers written
// either "m^2", "m2", "MPa^-0.5". A bare number is dimensionless.
Quantity parse_quantity(std::string_view text);

// SI value of one unit expression ("MPa" -> 1e6); throws UnitError.
Quantity parse_unit(std::string_view unit_expression);

}  // namespace outburst::units
