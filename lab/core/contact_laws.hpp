#pragma once
// The registry of contact laws: one table row per law. Adding a law is one file pair
// (contact_law_<name>.hpp with the stateless kernel, .cpp with mixing, validation and the
// entry) and one row in contact_laws.cpp.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lab/core/contact_model.hpp"
#include "lab/core/material.hpp"

namespace rocklab {

struct ContactLawEntry {
  std::string_view name;
  std::string_view doc;
  std::string_view material_keys;  // the material parameters the law reads
  // Throws InvalidParameter naming the material, key, range and unit.
  void (*validate)(const MaterialTable&);
  std::unique_ptr<ContactModel<2>> (*make2)(const MaterialTable&);
  std::unique_ptr<ContactModel<3>> (*make3)(const MaterialTable&);
};

const std::vector<const ContactLawEntry*>& contactLaws();
// The entry of a law by name; throws std::invalid_argument listing the known laws.
const ContactLawEntry& contactLaw(std::string_view name);

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
