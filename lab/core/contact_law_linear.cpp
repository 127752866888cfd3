#include "lab/core/contact_law_linear.hpp"

#include "lab/core/contact_laws.hpp"
#include "lab/core/contact_model_impl.hpp"
#include "lab/core/errors.hpp"

namespace rocklab {

namespace {

void validate(const MaterialTable& m) {
  for (const Material& a : m.all()) {
    const std::string where = "material '" + a.name + "' (linear contact law)";
    requireRange(where, "kn", a.kn, 0.0, false, INFINITY, true, "N/m");
    requireRange(where, "modulus", a.modulus, 0.0, false, INFINITY, true, "Pa");
    if (a.modulus > 0.0) {
      requireRange(where, "stiffness_ratio", a.stiffness_ratio, 0.0, true, INFINITY, true, "-");
    }
    if (!(a.kn > 0.0) && !(a.modulus > 0.0)) {
      throw InvalidParameter(where, "kn", a.kn, "(0, inf) or a modulus > 0", "N/m");
    }
    requireRange(where, "ks", a.ks, 0.0, false, INFINITY, true, "N/m");
    requireRange(where, "friction", a.friction, 0.0, false, INFINITY, true, "-");
    requireRange(where, "damping_ratio", a.damping_ratio, 0.0, false, 1.0, true, "-");
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
    "kn (N/m), ks (N/m) and/or modulus (Pa), stiffness_ratio (-); friction (-), "
    "damping_ratio (-)",
    validate,
    make<2>,
    make<3>,
};

}  // namespace rocklab
