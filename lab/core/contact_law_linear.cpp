#include "lab/core/contact_law_linear.hpp"

#include "lab/core/contact_laws.hpp"
#include "lab/core/contact_model_impl.hpp"
#include "lab/core/errors.hpp"

namespace rocklab {

namespace {

// The stiffness comes from particle springs (kn, ks: library settings, the paper's PFC 3
// style), from a contact modulus (a protocol's `material.contact_modulus_GPa`), or both.
void validate(const MaterialTable& m) {
  for (const Material& a : m.all()) {
    const std::string where = "material '" + a.name + "' (linear contact law)";
    requireRange(where, "kn", a.kn, 0.0, false, INFINITY, true, "N/m");
    requireRange(where, "ks", a.ks, 0.0, false, INFINITY, true, "N/m");
    // A modulus of 0 leaves the springs alone (its declared range is the protocol's, > 0).
    if (a.modulus != 0.0) {
      checkMaterialKeys(a, kLinearLawEntry);
    } else {
      checkFields(a, where);
    }
    if (!(a.kn > 0.0) && !(a.modulus > 0.0)) {
      throw InvalidParameter(where, "kn", a.kn, "(0, inf) or a modulus > 0", "N/m");
    }
  }
}

// Particle springs act in series at a contact, as in PFC (Itasca 1999):
// k = k1 k2 / (k1 + k2); a shear spring of 0 on either side gives no shear stiffness.
double series(double a, double b) {
  return a > 0.0 && b > 0.0 ? a * b / (a + b) : 0.0;
}

LinearParams mix(const MaterialTable& m, std::uint16_t a, std::uint16_t b) {
  LinearParams p;
  p.kn = series(m[a].kn, m[b].kn);
  p.ks = series(m[a].ks, m[b].ks);
  // Moduli combine like springs of equal length in series: the harmonic mean.
  p.modulus = 2.0 * series(m[a].modulus, m[b].modulus);
  p.shear_modulus =
      2.0 * series(m[a].modulus / m[a].stiffness_ratio, m[b].modulus / m[b].stiffness_ratio);
  p.mu = m.friction(a, b);
  p.damp = 2.0 * m.dampingRatio(a, b);
  return p;
}

template <int D>
std::unique_ptr<ContactModel<D>> make(const MaterialTable& m) {
  return bindContactLaw<D, LinearLaw>("linear", PairTable<LinearParams>(m, mix), m.all());
}

}  // namespace

const ContactLawEntry kLinearLawEntry{
    "linear",
    "linear normal and shear springs: particle springs in series and/or a contact modulus "
    "(kn = E A / L), Coulomb friction, dashpots by critical damping ratio",
    {{&Material::modulus,
      {"contact_modulus_GPa", units::GPa, Range::leftOpen(0, 1e4),
       "linear: contact modulus E, kn = E A / L per contact (PFC 5 deformability)"}},
     {&Material::stiffness_ratio,
      {"stiffness_ratio", units::none, Range::leftOpen(0, 100),
       "linear: kn / ks of the contacts"}}},
    validate,
    make<2>,
    make<3>,
};

}  // namespace rocklab
