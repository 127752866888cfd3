#include "lab/core/contact_laws.hpp"

#include <stdexcept>

#include "lab/core/contact_law_hertz.hpp"
#include "lab/core/contact_law_linear.hpp"

namespace rocklab {

const std::vector<const ContactLawEntry*>& contactLaws() {
  static const std::vector<const ContactLawEntry*> table = {
      &kLinearLawEntry,
      &kHertzLawEntry,
  };
  return table;
}

const ContactLawEntry& contactLaw(std::string_view name) {
  std::string known;
  for (const ContactLawEntry* e : contactLaws()) {
    if (e->name == name) return *e;
    known += (known.empty() ? "" : ", ") + std::string(e->name);
  }
  throw std::invalid_argument("unknown contact law '" + std::string(name) +
                              "'; known laws: " + known);
}

}  // namespace rocklab
