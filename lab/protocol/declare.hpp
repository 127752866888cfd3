#pragma once
// Settings structs and protocol files: the schema is built from the structs' field
// declarations (lab/core/fields.hpp), their member initialisers giving the defaults, and a
// protocol's settings are read back into the structs in SI, checked by the structs' own
// rules. A protocol default is therefore the library default, bit for bit: declaring a
// default its key's unit cannot carry back exactly is refused (a std::logic_error, which
// every test that builds a schema would hit).

#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "lab/core/fields.hpp"
#include "lab/protocol/params.hpp"

namespace rocklab::protocol {

// Adds a settings struct's fields to a schema, their defaults the struct's values.
class SchemaBuilder {
 public:
  SchemaBuilder(Schema& schema, std::string prefix = {})
      : schema_(schema), prefix_(std::move(prefix)) {}

  void operator()(const double& v, const Field& f) { add(f, Kind::Real, Value(si(v, f))); }
  void operator()(const std::vector<double>& v, const Field& f) {
    std::vector<double> shown;
    for (double x : v) shown.push_back(si(x, f));
    add(f, Kind::RealList, Value(shown));
  }
  template <class I>
  requires std::is_integral_v<I> &&(!std::is_same_v<I, bool>)void operator()(const I& v,
                                                                             const Field& f) {
    add(f, Kind::Integer, Value(static_cast<std::int64_t>(v)));
  }
  void operator()(const bool& v, const Field& f) { add(f, Kind::Flag, Value(v)); }
  void operator()(const std::string& v, const Field& f) { add(f, Kind::Text, Value(v)); }
  void operator()(const std::vector<std::string>& v, const Field& f) {
    add(f, Kind::TextList, Value(v));
  }
  template <class E, class C>
  void operator()(const E& v, const Field& f, const C& choices) {
    ParamDecl& d = add(f, Kind::Choice, Value(std::string(choiceName(v, choices))));
    for (const auto& c : choices) d.choices.emplace_back(c.name);
    if (!f.required && std::get<std::string>(*d.fallback).empty()) {
      throw std::logic_error(d.key + ": the default is none of the choices");
    }
  }
  SchemaBuilder at(std::string_view prefix) {
    return SchemaBuilder(schema_, prefix_ + std::string(prefix));
  }
  template <class S>
  void section(std::string_view prefix, const S& part) {
    SchemaBuilder inner = at(prefix);
    const_cast<S&>(part).fields(inner);  // fields() only names the members: nothing changes
  }

 private:
  // The default in the key's unit; it must convert back to the very same SI value.
  double si(double v, const Field& f) const {
    const double shown = f.unit.fromSi(v);
    const double back = f.unit.toSi(shown);
    if (!f.required && std::memcmp(&back, &v, sizeof v) != 0) {
      throw std::logic_error(prefix_ + std::string(f.key) + ": the default " +
                             Range::formatNumber(v) + " (SI) does not convert to " +
                             std::string(f.unit.name) + " and back exactly");
    }
    return shown;
  }
  ParamDecl& add(const Field& f, Kind kind, Value fallback) {
    ParamDecl d;
    d.key = prefix_ + std::string(f.key);
    d.kind = kind;
    d.unit = kind == Kind::Real || kind == Kind::RealList            ? f.unit
             : kind == Kind::Integer                                 ? units::none
             : kind == Kind::Text && f.unit.name == units::path.name ? units::path
                                                                     : units::text;
    if (!f.required) d.fallback = std::move(fallback);
    d.range = f.range;
    d.doc = std::string(f.doc);
    return schema_.add(std::move(d));
  }
  Schema& schema_;
  std::string prefix_;
};

// Fills a settings struct from protocol settings (numbers to SI), then checks the rules
// across its fields (validate()), reported as `file:line: key: why`.
class SettingsReader {
 public:
  SettingsReader(const Settings& s, std::string prefix = {}) : s_(s), prefix_(std::move(prefix)) {}

  void operator()(double& v, const Field& f) const { v = f.unit.toSi(s_.real(key(f))); }
  void operator()(std::vector<double>& v, const Field& f) const {
    v.clear();
    for (double x : s_.list(key(f))) v.push_back(f.unit.toSi(x));
  }
  template <class I>
  requires std::is_integral_v<I> &&(!std::is_same_v<I, bool>)void operator()(I& v,
                                                                             const Field& f) const {
    v = static_cast<I>(s_.integer(key(f)));
  }
  void operator()(bool& v, const Field& f) const { v = s_.flag(key(f)); }
  void operator()(std::string& v, const Field& f) const {
    v = f.unit.name == units::path.name ? s_.path(key(f)) : s_.text(key(f));
  }
  void operator()(std::vector<std::string>& v, const Field& f) const { v = s_.texts(key(f)); }
  template <class E, class C>
  void operator()(E& v, const Field& f, const C& choices) const {
    const std::string& name = s_.text(key(f));
    for (const auto& c : choices) {
      if (c.name == name) {
        v = c.value;
        return;
      }
    }
    throw std::logic_error(key(f) + " = " + name + ": not one of its choices");
  }
  SettingsReader at(std::string_view prefix) const {
    return SettingsReader(s_, prefix_ + std::string(prefix));
  }
  template <class S>
  void section(std::string_view prefix, S& part) const {
    const SettingsReader inner = at(prefix);
    part.fields(inner);
    if constexpr (Validated<S>) {
      try {
        part.validate();
      } catch (const InvalidParameter& e) {
        const std::string k = inner.prefix_ + e.key();
        throw ProtocolError({s_.where(k) + ": " + k + e.detail()});
      }
    }
  }

 private:
  std::string key(const Field& f) const { return prefix_ + std::string(f.key); }
  const Settings& s_;
  std::string prefix_;
};

// The schema of a settings struct's fields, its defaults those of `defaults`.
template <class S>
void declare(Schema& schema, const S& defaults = S{}) {
  SchemaBuilder(schema).section("", defaults);
}

// A settings struct read from protocol settings declared by declare<S>.
template <class S>
S read(const Settings& settings) {
  S out{};
  SettingsReader(settings).section("", out);
  return out;
}

}  // namespace rocklab::protocol
