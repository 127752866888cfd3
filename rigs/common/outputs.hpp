#pragma once
// A rig's outputs, declared once beside the rig (rigs/<rig>/outputs.cpp): the series,
// results and events it records, under which prefixes, and the key results a protocol may
// name in `protocol.key_results`. From this declaration `rocklab keys` lists them, protocol
// checking accepts key results, `rocklab run` refuses to record anything undeclared
// (CheckedRecorder), and the tests hold the report figures and key-result definitions to it.
//
// A name is `prefix + base`: the prefix says which stage, branch or test (`formation.`,
// `cored.`, `test2.`), the base what was measured. In a declared prefix or base '#' stands
// for a number and '*' for a word of [a-z0-9_] (`cycle#_modulus_ratio`, `solver_*_seconds`).
// Every declared prefix may go with every declared base of the rig.
// This library needs nothing but the standard library, so reports can read it.

#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace rocklab::rigs {

enum class OutputKind { Series, Result, Event };

struct OutputDecl {
  std::string_view name;  // the base name (for events, the kind)
  std::string_view unit;  // "-" for none
  std::string_view doc;
};

class Outputs {
 public:
  Outputs& prefixes(std::initializer_list<std::string_view> p);
  Outputs& series(std::initializer_list<OutputDecl> d);
  Outputs& results(std::initializer_list<OutputDecl> d);
  Outputs& events(std::initializer_list<OutputDecl> d);
  Outputs& keyResults(std::initializer_list<OutputDecl> d);
  Outputs& add(const Outputs& other);  // another declaration's prefixes and outputs too

  // Whether `name` is a declared prefix plus a declared base of that kind.
  bool declares(OutputKind kind, std::string_view name) const;
  // The key result a possibly prefixed name ("test2.ucs_MPa") stands for, or nullptr.
  const OutputDecl* keyResult(std::string_view name) const;
  const std::vector<OutputDecl>& keyResults() const { return key_results_; }
  const std::vector<OutputDecl>& of(OutputKind kind) const;
  const std::vector<std::string>& prefixes() const { return prefixes_; }
  // `rocklab keys`' second part: the key results, then what the rig records.
  std::string help() const;

 private:
  // The base of `name` under one of the prefixes (which may match more than one way).
  template <class Visit>
  void bases(std::string_view name, Visit&& visit) const;
  std::vector<std::string> prefixes_{""};
  std::vector<OutputDecl> series_, results_, events_, key_results_;
};

// Whether all of `name` matches a declared `pattern` ('#' a number, '*' a word).
bool outputNameMatches(std::string_view pattern, std::string_view name);

// What every specimen records (rigs/common/measurements.hpp, formation.hpp): the state
// series, the formation and cement results, the break events.
const Outputs& specimenOutputs();

// What every test on a specimen out of its box records (rigs/common/release.hpp): the
// specimen's, the unloading, the relaxation and the loading's peak, breaks and calm.
const Outputs& unconfinedOutputs();

// Each rig's, declared beside it (rigs/<rig>/outputs.cpp).
namespace oedometer {
const Outputs& outputs();
}
namespace biaxial {
const Outputs& outputs();
}
namespace envelope {
const Outputs& outputs();
}
namespace hydrostatic {
const Outputs& outputs();
}
namespace permeameter {
const Outputs& outputs();
}
namespace ultrasonic {
const Outputs& outputs();
}
namespace brazilian {
const Outputs& outputs();
}
namespace direct_tension {
const Outputs& outputs();
}
namespace ucs {
const Outputs& outputs();
}

// A rig's outputs by its name (the rig table's names, rigs/registry.cpp), or nullptr.
const Outputs* rigOutputs(std::string_view rig);

}  // namespace rocklab::rigs
