#pragma once
// Settings declared once. A settings struct names every field a protocol can set in one
// member function, `template <class F> void fields(F& f)`, the way `visit` names what a
// checkpoint stores (archive.hpp): the field's key (its unit in its name), the unit, the
// allowed range and a one-line doc. The struct's member initialisers are the defaults.
// From that one declaration come the protocol schema and its validation, `rocklab keys`,
// the notebook's parameter rows (lab/protocol/declare.hpp) and the core's own checks
// (checkFields below): a library default, a protocol default and a range cannot disagree.
//
//   struct Spring {
//     double stiffness = 1e6;  // N/m
//     template <class F>
//     void fields(F& f) {
//       f(stiffness, {"stiffness_N_per_m", units::N_per_m, Range::leftOpen(0, 1e12), "..."});
//     }
//   };
//
// A visitor `f` offers:
//   f(member, field)             a number, integer, flag, text, or a list of numbers or texts
//   f(member, field, choices)    one of named values (a range of Choice): an enum, or a text
//   f.section("prefix.", part)   part's own fields, their keys under the prefix; a part with
//                                `void validate() const` has its rules across fields checked
//   f.at("prefix.")              a visitor whose keys go under the prefix (a struct's
//                                fields in several protocol sections)
// Numbers are stored in SI; the key's unit converts (degrees to radians included).

#include <cmath>
#include <cstdint>
#include <numbers>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "lab/core/errors.hpp"

namespace rocklab {

// The unit a key names, and its conversion to SI.
struct Unit {
  std::string_view name;  // as in the key: "MPa"; "-" for none, "" for texts
  double factor = 1.0;    // SI = value * factor
  bool degrees = false;   // SI = value * pi / 180 (radians)

  double toSi(double v) const { return degrees ? v * std::numbers::pi / 180.0 : v * factor; }
  double fromSi(double v) const { return degrees ? v * 180.0 / std::numbers::pi : v / factor; }
};

namespace units {
inline constexpr Unit none{"-"};     // dimensionless numbers and counts
inline constexpr Unit text{""};      // texts, flags and choices
inline constexpr Unit path{"path"};  // a file, relative to the protocol file that names it
inline constexpr Unit m{"m"};
inline constexpr Unit mm{"mm", 1e-3};
inline constexpr Unit s{"s"};
inline constexpr Unit per_s{"1/s"};
inline constexpr Unit kPa{"kPa", 1e3};
inline constexpr Unit MPa{"MPa", 1e6};
inline constexpr Unit GPa{"GPa", 1e9};
inline constexpr Unit MPa_per_s{"MPa/s", 1e6};
inline constexpr Unit mPa_s{"mPa s", 1e-3};
inline constexpr Unit kg_per_m3{"kg/m^3"};
inline constexpr Unit m_per_s{"m/s"};
inline constexpr Unit kHz{"kHz", 1e3};
inline constexpr Unit deg{"deg", 1.0, true};
inline constexpr Unit phi{"phi"};  // Krumbein's grain size scale, -log2(d / 1 mm)
}  // namespace units

// Shorthands for defaults written in a key's unit: `4.0 * kGPa` is exactly what the key's
// conversion gives for 4 (the same multiplication).
inline constexpr double kMPa = units::MPa.factor;
inline constexpr double kGPa = units::GPa.factor;
inline constexpr double kmm = units::mm.factor;

// Allowed values of a number, in the key's unit.
struct Range {
  double lo = -INFINITY, hi = INFINITY;
  bool lo_open = false, hi_open = false;

  static constexpr Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static constexpr Range leftOpen(double lo, double hi) { return {lo, hi, true, false}; }
  static constexpr Range rightOpen(double lo, double hi) { return {lo, hi, false, true}; }
  static constexpr Range open(double lo, double hi) { return {lo, hi, true, true}; }

  bool contains(double v) const {
    const bool above = lo_open ? v > lo : v >= lo;
    const bool below = hi_open ? v < hi : v <= hi;
    return above && below && v == v;
  }
  // "(0, 10000]"
  std::string text() const {
    std::ostringstream s;
    s.precision(10);
    s << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
    return s.str();
  }
  // Ten significant digits, as protocols and `rocklab keys` show numbers.
  static std::string formatNumber(double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
  }
};

// One field's declaration.
struct Field {
  std::string_view key;  // relative to its section's prefix
  Unit unit = units::none;
  Range range = {};  // numbers and each element of a list of numbers
  std::string_view doc;
  bool required = false;  // no default: a protocol must give it
};

// A named value of a choice field.
template <class T>
struct Choice {
  std::string_view name;
  T value;
};

template <class T>
concept Validated = requires(const T& t) {
  t.validate();
};

// The name of `value` among `choices`, a range of Choice ("" when it is none of them).
template <class T, class C>
std::string_view choiceName(const T& value, const C& choices) {
  for (const auto& c : choices) {
    if (c.value == value) return c.name;
  }
  return {};
}

// Checks every declared field of `settings` against its range or choices, then the
// settings' own rules (validate()); throws InvalidParameter naming `where`, the key (with
// its section prefix), the value in the key's unit, the range and the unit.
class FieldChecker {
 public:
  explicit FieldChecker(std::string where, std::string prefix = {})
      : where_(std::move(where)), prefix_(std::move(prefix)) {}

  void operator()(const double& v, const Field& f) const { number(f.unit.fromSi(v), f); }
  void operator()(const std::vector<double>& v, const Field& f) const {
    for (double x : v) number(f.unit.fromSi(x), f);
  }
  template <class I>
  requires std::is_integral_v<I> &&(!std::is_same_v<I, bool>)void operator()(const I& v,
                                                                             const Field& f) const {
    number(static_cast<double>(v), f);
  }
  void operator()(const bool&, const Field&) const {}
  void operator()(const std::string&, const Field&) const {}
  void operator()(const std::vector<std::string>&, const Field&) const {}
  template <class E, class C>
  void operator()(const E& v, const Field& f, const C& choices) const {
    if (choiceName(v, choices).empty()) {
      std::string allowed;
      for (const auto& c : choices) allowed += (allowed.empty() ? "" : ", ") + std::string(c.name);
      throw InvalidParameter(where_, prefix_ + std::string(f.key), "is not one of: " + allowed);
    }
  }
  FieldChecker at(std::string_view prefix) const {
    return FieldChecker(where_, prefix_ + std::string(prefix));
  }
  template <class S>
  void section(std::string_view prefix, const S& part) const {
    FieldChecker inner = at(prefix);
    const_cast<S&>(part).fields(inner);  // fields() only names the members: nothing changes
    if constexpr (Validated<S>) {
      try {
        part.validate();
      } catch (const InvalidParameter& e) {
        throw e.within(where_, prefix_ + std::string(prefix));
      }
    }
  }

 private:
  void number(double v, const Field& f) const {
    if (f.range.contains(v)) return;
    throw InvalidParameter(where_, prefix_ + std::string(f.key), v, f.range.text(),
                           std::string(f.unit.name));
  }
  std::string where_, prefix_;
};

// Checks a settings struct (see FieldChecker).
template <class S>
void checkFields(const S& settings, const std::string& where) {
  FieldChecker(where).section("", settings);
}

}  // namespace rocklab
