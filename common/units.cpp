#include "common/units.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fmt/format.h>

namespace outburst::units {

namespace {

bool near(double a, double b) { return std::abs(a - b) < 1e-9; }

struct NamedUnit {
  std::string_view symbol;
  double si;
  Dimension dimension;
};

constexpr double pi = 3.14159265358979323846;

// Symbols are matched exactly (case sensitive): "t" is the tonne, "d" the day.
constexpr std::array<NamedUnit, 33> known_units{{
    {"m", 1.0, length},
    {"cm", 1e-2, length},
    {"mm", 1e-3, length},
    {"km", 1e3, length},
    {"s", 1.0, time},
    {"ms", 1e-3, time},
    {"us", 1e-6, time},
    {"min", 60.0, time},
    {"h", 3600.0, time},
    {"d", 86400.0, time},
    {"day", 86400.0, time},
    {"a", 365.25 * 86400.0, time},
    {"kg", 1.0, mass},
    {"g", 1e-3, mass},
    {"t", 1e3, mass},
    {"N", 1.0, {1, 1, -2, 0}},
    {"kN", 1e3, {1, 1, -2, 0}},
    {"MN", 1e6, {1, 1, -2, 0}},
    {"Pa", 1.0, pressure},
    {"kPa", 1e3, pressure},
    {"MPa", 1e6, pressure},
    {"GPa", 1e9, pressure},
    {"bar", 1e5, pressure},
    {"J", 1.0, {2, 1, -2, 0}},
    {"kJ", 1e3, {2, 1, -2, 0}},
    {"MJ", 1e6, {2, 1, -2, 0}},
    {"W", 1.0, {2, 1, -3, 0}},
    {"deg", pi / 180.0, angle},
    {"rad", 1.0, angle},
    {"L", 1e-3, {3, 0, 0, 0}},
    {"Hz", 1.0, {0, 0, -1, 0}},
    {"mPa", 1e-3, pressure},
    {"uPa", 1e-6, pressure},
}};

struct NamedDimension {
  std::string_view name;
  Dimension dimension;
};

const std::array<NamedDimension, 20> named_dimensions{{
    {"dimensionless number", dimensionless},
    {"length", length},
    {"mass", mass},
    {"time", time},
    {"angle", angle},
    {"pressure", pressure},
    {"velocity", velocity},
    {"acceleration", acceleration},
    {"density", density},
    {"inverse pressure", inverse_pressure},
    {"area", area},
    {"viscosity", viscosity},
    {"gas conductivity (area / (pressure^2 time))", gas_conductivity},
    {"mobility (area / (pressure time))", mobility},
    {"gas content coefficient per volume (pressure^-1/2)", gas_content_per_volume},
    {"gas content coefficient per mass (volume / (mass pressure^1/2))",
     gas_content_per_mass},
    {"force per length", {0, 1, -2, 0}},
    {"force", force},
    {"frequency", {0, 0, -1, 0}},
    {"energy", {2, 1, -2, 0}},
}};

// Recursive-descent parser over a unit expression:
//   expr   := factor { ('*' | '.' | ' ' | '/') factor }
//   factor := ( symbol | '(' expr ')' ) [ '^' number | digits ]
// Each '(' is a level of recursion: parentheses nested deeper than any unit
// needs are refused before they exhaust the stack (50,000 of them did).
class UnitParser {
 public:
  explicit UnitParser(std::string_view text) : text_(text) {}

  Quantity parse() {
    Quantity q = expression();
    skip_spaces();
    if (pos_ != text_.size())
      fail(fmt::format("unexpected '{}'", text_.substr(pos_)));
    return q;
  }

 private:
  static constexpr int max_depth = 32;
  std::string_view text_;
  std::size_t pos_ = 0;
  int depth_ = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw UnitError(fmt::format("cannot read the unit \"{}\": {}", text_, what));
  }

  void skip_spaces() {
    while (pos_ < text_.size() && text_[pos_] == ' ') ++pos_;
  }

  bool at_factor_start() {
    skip_spaces();
    return pos_ < text_.size() &&
           (std::isalpha(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '(');
  }

  Quantity expression() {
    Quantity q = factor();
    for (;;) {
      skip_spaces();
      if (pos_ >= text_.size() || text_[pos_] == ')') return q;
      const char c = text_[pos_];
      bool divide = false;
      if (c == '/') {
        divide = true;
        ++pos_;
      } else if (c == '*' || c == '.') {
        ++pos_;
      } else if (!at_factor_start()) {
        fail(fmt::format("unexpected '{}'", text_.substr(pos_)));
      }
      const Quantity rhs = factor();
      if (divide) {
        q.si /= rhs.si;
        q.dimension = q.dimension / rhs.dimension;
      } else {
        q.si *= rhs.si;
        q.dimension = q.dimension * rhs.dimension;
      }
    }
  }

  Quantity factor() {
    skip_spaces();
    Quantity base;
    if (pos_ < text_.size() && text_[pos_] == '(') {
      if (++depth_ > max_depth)
        fail(fmt::format("parentheses nested deeper than {} levels (at character {})", max_depth, pos_ + 1));
      ++pos_;
      base = expression();
      --depth_;
      skip_spaces();
      if (pos_ >= text_.size() || text_[pos_] != ')') fail("missing ')'");
      ++pos_;
    } else if (text_.substr(pos_, 1) == "1" &&
               (pos_ + 1 == text_.size() || !std::isdigit(static_cast<unsigned char>(text_[pos_ + 1])))) {
      ++pos_;  // "1/Pa": the unit one, as a numerator
      base = {1.0, dimensionless};
    } else {
      const std::size_t start = pos_;
      while (pos_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[pos_])))
        ++pos_;
      const std::string_view symbol = text_.substr(start, pos_ - start);
      if (symbol.empty()) fail("expected a unit symbol");
      base = lookup(symbol);
    }
    const double exponent = optional_exponent();
    const double si = std::pow(base.si, exponent);
    if (!std::isfinite(si) || si == 0)
      fail(fmt::format("the power ^{:g} takes the unit beyond the range of numbers (about 1e-308 to 1e308)", exponent));
    return {si, base.dimension.pow(exponent)};
  }

  double optional_exponent() {
    if (pos_ < text_.size() && text_[pos_] == '^') {
      ++pos_;
      return number("an exponent after '^'", true);
    }
    if (pos_ < text_.size() &&
        (std::isdigit(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '-'))
      return number("an exponent", false);
    return 1.0;
  }

  // After '^' an exponent may be written in scientific notation ("^1e-1"); a
  // bare one ("m2") may not, or "m2e" would swallow the start of a unit.
  double number(const char* what, bool scientific) {
    const std::size_t start = pos_;
    const auto digit_or_sign = [&](std::size_t at) {
      return at < text_.size() && (std::isdigit(static_cast<unsigned char>(text_[at])) || text_[at] == '-' ||
                                   text_[at] == '+');
    };
    while (pos_ < text_.size() &&
           (std::isdigit(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '.' ||
            text_[pos_] == '-' || text_[pos_] == '+' ||
            (scientific && pos_ > start && (text_[pos_] == 'e' || text_[pos_] == 'E') && digit_or_sign(pos_ + 1))))
      ++pos_;
    double value = 0;
    const auto [end, ec] = std::from_chars(text_.data() + start, text_.data() + pos_, value);
    if (ec == std::errc::result_out_of_range)
      fail(fmt::format("{} is out of range", text_.substr(start, pos_ - start)));
    if (ec != std::errc() || end != text_.data() + pos_ || start == pos_)
      fail(fmt::format("expected {}", what));
    return value;
  }

  Quantity lookup(std::string_view symbol) const {
    for (const auto& u : known_units)
      if (u.symbol == symbol) return {u.si, u.dimension};
    std::string list;
    for (const auto& u : known_units) list += fmt::format("{} ", u.symbol);
    fail(fmt::format("unknown unit '{}' (known: {})", symbol, list));
  }
};

}  // namespace

bool Dimension::operator==(const Dimension& o) const {
  return near(length, o.length) && near(mass, o.mass) && near(time, o.time) &&
         near(angle, o.angle);
}

Dimension Dimension::operator*(const Dimension& o) const {
  return {length + o.length, mass + o.mass, time + o.time, angle + o.angle};
}

Dimension Dimension::operator/(const Dimension& o) const {
  return {length - o.length, mass - o.mass, time - o.time, angle - o.angle};
}

Dimension Dimension::pow(double e) const {
  return {length * e, mass * e, time * e, angle * e};
}

std::string describe(const Dimension& d) {
  for (const auto& named : named_dimensions)
    if (named.dimension == d) return std::string(named.name);
  std::string formula;
  const std::array<std::pair<const char*, double>, 4> parts{
      {{"m", d.length}, {"kg", d.mass}, {"s", d.time}, {"rad", d.angle}}};
  for (const auto& [symbol, exponent] : parts) {
    if (near(exponent, 0)) continue;
    if (!formula.empty()) formula += ' ';
    formula += near(exponent, 1) ? std::string(symbol) : fmt::format("{}^{:g}", symbol, exponent);
  }
  return formula;
}

std::string symbol(const Dimension& d) {
  for (const auto& u : known_units)
    if (u.dimension == d) return std::string(u.symbol);
  return {};
}

Quantity parse_unit(std::string_view unit_expression) {
  return UnitParser(unit_expression).parse();
}

Quantity parse_quantity(std::string_view text) {
  std::size_t start = 0;
  while (start < text.size() && text[start] == ' ') ++start;
  double value = 0;
  const char* first = text.data() + start;
  const char* last = text.data() + text.size();
  auto [end, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::result_out_of_range)
    throw UnitError(fmt::format("the number in \"{}\" is beyond the range of numbers (about 1e-308 to 1e308)", text));
  if (ec != std::errc() || end == first)
    throw UnitError(fmt::format("\"{}\" does not start with a number", text));
  // from_chars reads "nan" and "inf" too, which no unit makes finite.
  if (std::isnan(value))
    throw UnitError(fmt::format("\"{}\" starts with NaN, which is not a value; give a finite number", text));
  if (std::isinf(value))
    throw UnitError(fmt::format("\"{}\" starts with an infinite number; give a finite one", text));
  std::string_view rest(end, static_cast<std::size_t>(last - end));
  while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
  while (!rest.empty() && rest.back() == ' ') rest.remove_suffix(1);
  if (rest.empty()) return {value, dimensionless};
  const Quantity unit = parse_unit(rest);
  const double si = value * unit.si;
  if (!std::isfinite(si))
    throw UnitError(fmt::format("\"{}\" overflows: in SI it exceeds the largest number (about 1.8e308)", text));
  if (si == 0 && value != 0)
    throw UnitError(fmt::format("\"{}\" underflows: in SI it is below the smallest number (about 1e-308)", text));
  return {si, unit.dimension};
}

}  // namespace outburst::units
