// The identity a formed sample is kept under (rigs/common/formed_samples.hpp): what the
// formation depends on changes it, what acts only after the formation does not.
#include <gtest/gtest.h>

#include "rigs/common/formed_samples.hpp"
#include "rigs/registry.hpp"

namespace rocklab::testing {
namespace {

std::string identityWith(const std::vector<std::string>& sets) {
  std::vector<protocol::Override> overrides;
  for (const std::string& s : sets) overrides.push_back(protocol::parseOverride(s));
  const rigs::CheckedProtocol c =
      rigs::checkProtocolText("formed.toml",
                              "[protocol]\nname = \"formed\"\nrig = \"biaxial\"\ndimension = 2\n"
                              "[sample]\nkind = \"grains\"\ncount = 50\n[bonds]\nenabled = true\n"
                              "[loading]\naxial_strain_rate_per_s = 1.0\n",
                              overrides);
  return rigs::formationIdentity(c.settings);
}

TEST(FormedSamples, TheIdentityHoldsWhatTheFormationDependsOnAndNothingElse) {
  const std::string base = identityWith({});
  EXPECT_NE(base.find("rig = biaxial"), std::string::npos) << base;
  // Used after the formation, or not physics: the same formation.
  for (const char* after :
       {"protocol.name=other", "bonds.tensile_strength_mean_MPa=20", "bonds.gap_ratio=0.2",
        "grain_bonds.tensile_strength_mean_MPa=70", "grain_bonds.shear_strength_std_MPa=3",
        "numerics.density_scaling=4", "loading.axial_strain_rate_per_s=0.5",
        "loading.confining_stress_MPa=4", "formation.reuse=true", "output.checkpoint_every_s=5"}) {
    EXPECT_EQ(identityWith({after}), base) << after;
  }
  // What the packing, the forming or the grains' stiffness depend on: another formation.
  for (const char* before :
       {"protocol.seed=2", "sample.count=60", "material.friction=0.3", "formation.friction=0.1",
        "formation.axial_stress_MPa=2", "formation.density_scaling=2", "grain_bonds.modulus_GPa=50",
        "numerics.threads=2", "numerics.local_damping=0.5", "output.record_every_steps=100"}) {
    EXPECT_NE(identityWith({before}), base) << before;
  }
}

}  // namespace
}  // namespace rocklab::testing
