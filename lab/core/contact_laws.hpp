#pragma once
// The registry of contact laws: one table row per law. Adding a law is one file pair
// (contact_law_<name>.hpp with the stateless kernel, .cpp with mixing, validation and the
// entry) and one row in contact_laws.cpp. A row declares the material parameters its law
// reads from a protocol (`material.*` keys beside the common density, friction and damping
// of Material::fields); the protocol's choice of `material.contact_law` is the table's names.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lab/core/contact_model.hpp"
#include "lab/core/fields.hpp"
#include "lab/core/material.hpp"

namespace rocklab {

// A material parameter a law reads, with its protocol key (under `material.`).
struct MaterialKey {
  double Material::*member;
  Field field;
};

struct ContactLawEntry {
  std::string_view name;
  std::string_view doc;
  std::vector<MaterialKey> keys;  // the law's own material parameters a protocol sets
  // Throws InvalidParameter naming the material, key, range and unit.
  void (*validate)(const MaterialTable&);
  std::unique_ptr<ContactModel<2>> (*make2)(const MaterialTable&);
  std::unique_ptr<ContactModel<3>> (*make3)(const MaterialTable&);
};

const std::vector<const ContactLawEntry*>& contactLaws();
// The laws' names, as the choices of a settings field (SimulationConfig::contact_law).
const std::vector<Choice<std::string>>& contactLawChoices();
// The entry of a law by name; throws std::invalid_argument listing the known laws.
const ContactLawEntry& contactLaw(std::string_view name);

// Checks a material's common fields (Material::fields) and the law's own keys against their
// declarations; throws InvalidParameter naming the material, key, range and unit.
void checkMaterialKeys(const Material& m, const ContactLawEntry& law);

template <int D>
std::unique_ptr<ContactModel<D>> makeContactModel(std::string_view law, const MaterialTable& m) {
  const ContactLawEntry& e = contactLaw(law);
  e.validate(m);
  if constexpr (D == 2) {
    return e.make2(m);
  } else {
    return e.make3(m);
  }
}

}  // namespace rocklab
