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

const std::vector<Choice<std::string>>& contactLawChoices() {
  static const std::vector<Choice<std::string>> choices = [] {
    std::vector<Choice<std::string>> c;
    for (const ContactLawEntry* e : contactLaws()) c.push_back({e->name, std::string(e->name)});
    return c;
  }();
  return choices;
}

void checkMaterialKeys(const Material& m, const ContactLawEntry& law) {
  const FieldChecker check("material '" + m.name + "' (" + std::string(law.name) + " contact law)");
  check.section("", m);
  for (const MaterialKey& k : law.keys) check(m.*k.member, k.field);
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
