#include "lab/core/contact_law_hertz.hpp"

#include "lab/core/contact_laws.hpp"
#include "lab/core/contact_model_impl.hpp"
#include "lab/core/errors.hpp"

namespace rocklab {

namespace {

void validate(const MaterialTable& m) {
  for (const Material& a : m.all()) checkMaterialKeys(a, kHertzLawEntry);
}

// Effective moduli of two elastic bodies in contact (Johnson 1985, ch. 4 and 7):
// 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 and 1/G* = (2-nu1)/G1 + (2-nu2)/G2.
HertzParams mix(const MaterialTable& m, std::uint16_t a, std::uint16_t b) {
  const Material& A = m[a];
  const Material& B = m[b];
  const double ga = A.young / (2.0 * (1.0 + A.poisson)), gb = B.young / (2.0 * (1.0 + B.poisson));
  HertzParams p;
  p.estar =
      1.0 / ((1.0 - A.poisson * A.poisson) / A.young + (1.0 - B.poisson * B.poisson) / B.young);
  p.gstar = 1.0 / ((2.0 - A.poisson) / ga + (2.0 - B.poisson) / gb);
  p.mu = m.friction(a, b);
  p.damp = 2.0 * std::sqrt(5.0 / 6.0) * m.dampingRatio(a, b);
  p.cn_per_am = p.damp * std::sqrt(2.0 * p.estar);
  p.cs_per_am = p.damp * std::sqrt(8.0 * p.gstar);
  return p;
}

template <int D>
std::unique_ptr<ContactModel<D>> make(const MaterialTable& m) {
  return bindContactLaw<D, HertzLaw>("hertz", PairTable<HertzParams>(m, mix), m.all());
}

}  // namespace

const ContactLawEntry kHertzLawEntry{
    "hertz",
    "Hertz normal force, Mindlin no-slip tangential stiffness, Coulomb friction, Tsuji "
    "dashpots by damping ratio (2D disks use the sphere formula, as PFC2D does)",
    {{&Material::young,
      {"young_GPa", units::GPa, Range::leftOpen(0, 1e4), "hertz: Young's modulus of the grains"}},
     {&Material::poisson,
      {"poisson", units::none, Range::leftOpen(-1, 0.5), "hertz: Poisson's ratio of the grains"}}},
    validate,
    make<2>,
    make<3>,
};

}  // namespace rocklab
