// The contact kernels against hand calculations: normal laws, mixing, Coulomb sliding,
// dissipation, frame invariance; the law registry; and PFC's local damping.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <bit>
#include <cmath>
#include <limits>

#include "lab/core/contact_law_hertz.hpp"
#include "lab/core/contact_law_linear.hpp"
#include "lab/core/contact_laws.hpp"
#include "lab/core/errors.hpp"
#include "lab/core/local_damping.hpp"

namespace rocklab {
namespace {

// The branch-free local damping gives the bits of its defining product, -alpha |f| sign(v),
// for every sign and zero of force and velocity (a changed bit would change every settled
// sample's path).
TEST(LocalDamping, TheBranchFreeFormGivesTheBitsOfTheProduct) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double fs[] = {0.0, -0.0, 1.5, -1.5, 3e-310, -7.25e12, 1e300};
  const double vs[] = {0.0, -0.0, 2.0, -2.0, 4e-320, -1e-12, nan, -nan};
  for (const double alpha : {0.0, 0.3, 0.7}) {
    for (const double f : fs) {
      for (const double v : vs) {
        const double sign = v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
        const double product = -alpha * std::abs(f) * sign;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(localDamping(f, v, alpha)),
                  std::bit_cast<std::uint64_t>(product))
            << "alpha " << alpha << ", f " << f << ", v " << v;
      }
    }
  }
}

ContactKinematics<3> restingContact(double overlap, double r, double mstar) {
  ContactKinematics<3> k;
  k.n = Eigen::Vector3d::UnitX();
  k.overlap = overlap;
  k.vc = Eigen::Vector3d::Zero();
  k.spin_n = 0.0;
  k.shape = pairShape<3>(r, r, 1.0);
  k.mstar = mstar;
  return k;
}

TEST(LinearLaw, NormalForceIsSpringTimesOverlap) {
  LinearParams p{.kn = 1e6, .ks = 5e5, .mu = 0.5};
  Eigen::Vector3d fs = Eigen::Vector3d::Zero();
  ContactDissipation diss;
  const auto r =
      contactForce<3, LinearLaw, true>(p, restingContact(1e-6, 1e-3, 1e-3), fs, 1e-6, diss);
  EXPECT_DOUBLE_EQ(r.force.x(), 1.0);
  EXPECT_DOUBLE_EQ(r.force.y(), 0.0);
  EXPECT_DOUBLE_EQ(r.kn, 1e6);
}

TEST(HertzLaw, NormalForceMatchesHertz) {
  const double e = 70e9, nu = 0.25, r = 1e-3, overlap = 2e-6;
  MaterialTable m;
  Material a;
  a.young = e;
  a.poisson = nu;
  m.add(a);
  auto model = makeContactModel<3>("hertz", m);
  const ContactShape shape = pairShape<3>(r, r, 1.0);
  const double rstar = r / 2;
  const double estar = e / (2 * (1 - nu * nu));
  const double expected = 4.0 / 3.0 * estar * std::sqrt(rstar) * std::pow(overlap, 1.5);
  EXPECT_NEAR(model->normalForce(0, 0, overlap, shape), expected, 1e-12 * expected);
  const auto [kn, ks] = model->stiffness(0, 0, overlap, shape, 1.0);
  const double g = e / (2 * (1 + nu)), gstar = g / (2 * (2 - nu));
  EXPECT_NEAR(kn, 2 * estar * std::sqrt(rstar * overlap), 1e-6 * kn);
  EXPECT_NEAR(ks, 8 * gstar * std::sqrt(rstar * overlap), 1e-6 * ks);
  // Strain energy is the integral of the force: 2/5 F overlap for Hertz.
  EXPECT_NEAR(model->strainEnergy(0, 0, overlap, shape, 1.0, 0.0), 0.4 * expected * overlap, 1e-12);
}

TEST(ContactLaws, MixingRules) {
  MaterialTable m;
  Material a, b;
  a.kn = 2e6, a.ks = 1e6, a.friction = 0.6, a.damping_ratio = 0.1;
  b.kn = 2e6, b.ks = 0.0, b.friction = 0.2, b.damping_ratio = 0.3;
  a.modulus = b.modulus = 0.0;  // the particle springs alone
  m.add(a);
  m.add(b);
  auto lin = makeContactModel<3>("linear", m);
  // Springs in series; a shear spring of 0 on one side gives none.
  EXPECT_DOUBLE_EQ(lin->stiffness(0, 0, 1e-6, pairShape<3>(1e-3, 1e-3, 1.0), 1.0).first, 1e6);
  EXPECT_DOUBLE_EQ(lin->stiffness(0, 1, 1e-6, pairShape<3>(1e-3, 1e-3, 1.0), 1.0).second, 0.0);
  EXPECT_DOUBLE_EQ(m.friction(0, 1), 0.2);
  EXPECT_DOUBLE_EQ(m.dampingRatio(0, 1), 0.2);
  m.setPair(0, 1, {0.9, std::nullopt});
  EXPECT_DOUBLE_EQ(m.friction(1, 0), 0.9);
}

// PFC 5's deformability method: kn = E A / L with A = pi min(r)^2 (3D) or 2 min(r) t (2D)
// and L = r1 + r2; ks = kn / ratio.
TEST(ContactLaws, LinearStiffnessFromAModulus) {
  MaterialTable m;
  Material a;
  a.modulus = 4e9;
  a.stiffness_ratio = 2.0;
  m.add(a);
  const double r1 = 1e-3, r2 = 3e-3;
  const auto [kn, ks] =
      makeContactModel<3>("linear", m)->stiffness(0, 0, 1e-6, pairShape<3>(r1, r2, 1.0), 1.0);
  EXPECT_NEAR(kn, 4e9 * M_PI * r1 * r1 / (r1 + r2), 1e-9 * kn);
  EXPECT_NEAR(ks, kn / 2.0, 1e-9 * kn);
  const auto [kn2, ks2] =
      makeContactModel<2>("linear", m)->stiffness(0, 0, 1e-6, pairShape<2>(r1, r2, 0.5), 1.0);
  EXPECT_NEAR(kn2, 4e9 * 2 * r1 * 0.5 / (r1 + r2), 1e-9 * kn2);
  // On a wall, L is the particle's radius.
  const auto [knw, ksw] =
      makeContactModel<3>("linear", m)->stiffness(0, 0, 1e-6, wallShape<3>(r1, 1.0), 1.0);
  EXPECT_NEAR(knw, 4e9 * M_PI * r1, 1e-9 * knw);
}

TEST(ContactLaws, RegistryNamesLawsAndValidationNamesTheKey) {
  EXPECT_NO_THROW(contactLaw("linear"));
  EXPECT_NO_THROW(contactLaw("hertz"));
  try {
    contactLaw("jkr");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("linear, hertz"), std::string::npos) << e.what();
  }
  MaterialTable m;
  Material a;
  a.name = "sand";
  a.kn = -1.0;
  m.add(a);
  try {
    makeContactModel<3>("linear", m);
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.key(), "kn");
    EXPECT_EQ(e.unit(), "N/m");
    EXPECT_NE(std::string(e.what()).find("sand"), std::string::npos) << e.what();
  }
}

TEST(ContactKernel, CoulombCapsTheShearForceAndDissipatesSlip) {
  const double kn = 1e6, ks = 1e6, mu = 0.3, overlap = 1e-6, dt = 1e-6;
  LinearParams p{.kn = kn, .ks = ks, .mu = mu};
  auto k = restingContact(overlap, 1e-3, 1e-3);
  k.vc = {0.0, 2.0, 0.0};  // fast tangential motion: slides at once
  Eigen::Vector3d fs = Eigen::Vector3d::Zero();
  ContactDissipation diss;
  const auto r = contactForce<3, LinearLaw, true>(p, k, fs, dt, diss);
  const double fn = kn * overlap;
  EXPECT_NEAR(std::abs(r.force.y()), mu * fn, 1e-12);
  EXPECT_LT(r.force.y(), 0.0);  // opposes the motion of j relative to i
  // Slip = displacement minus the spring's extension: 2 m/s * dt - mu fn / ks.
  const double slip = 2.0 * dt - mu * fn / ks;
  EXPECT_NEAR(diss.friction, mu * fn * slip, 1e-15);
  // In the next step the spring stays at the cap.
  ContactDissipation d2;
  const auto r2 = contactForce<3, LinearLaw, true>(p, k, fs, dt, d2);
  EXPECT_NEAR(r2.force.y(), -mu * fn, 1e-12);
  EXPECT_NEAR(d2.friction, mu * fn * 2.0 * dt, 1e-15);
}

TEST(ContactKernel, ViscousDissipationIsDashpotPower) {
  const double kn = 1e6, beta = 0.3, m = 1e-3, vn = -0.5;
  LinearParams p{.kn = kn, .ks = 0.0, .mu = 0.5, .damp = 2 * beta};
  auto k = restingContact(1e-6, 1e-3, m);
  k.vc = {vn, 0.0, 0.0};
  Eigen::Vector3d fs = Eigen::Vector3d::Zero();
  ContactDissipation diss;
  const auto r = contactForce<3, LinearLaw, true>(p, k, fs, 1e-6, diss);
  const double c = 2 * beta * std::sqrt(m * kn);
  EXPECT_NEAR(r.force.x(), kn * 1e-6 - c * vn, 1e-12);
  EXPECT_NEAR(diss.viscous, c * vn * vn * 1e-6, 1e-18);
}

// Rotating the whole contact (normal, relative velocity and stored spring force) rotates
// the result: the kernel has no preferred frame.
TEST(ContactKernel, FrameInvariant) {
  HertzParams p{.estar = 37e9, .gstar = 8e9, .mu = 0.4, .damp = 0.1};
  ContactKinematics<3> k;
  k.n = Eigen::Vector3d(1, 2, 2).normalized();
  k.overlap = 3e-6;
  k.vc = Eigen::Vector3d(0.01, -0.03, 0.02);
  k.spin_n = 40.0;
  k.shape = pairShape<3>(1e-3, 1e-3, 1.0);
  k.mstar = 4e-6;
  Eigen::Vector3d fs = Eigen::Vector3d(0.2, 0.1, -0.2);
  fs -= fs.dot(k.n) * k.n;
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  ContactKinematics<3> kr = k;
  kr.n = rot * k.n;
  kr.vc = rot * k.vc;
  Eigen::Vector3d fs_r = rot * fs;
  ContactDissipation d1, d2;
  const auto a = contactForce<3, HertzLaw, true>(p, k, fs, 1e-7, d1);
  const auto b = contactForce<3, HertzLaw, true>(p, kr, fs_r, 1e-7, d2);
  EXPECT_LT((rot * a.force - b.force).norm(), 1e-12 * a.force.norm());
  EXPECT_LT((rot * fs - fs_r).norm(), 1e-12 * fs.norm());
  EXPECT_NEAR(d1.viscous, d2.viscous, 1e-12 * d1.viscous);
}

// The stored spring force turns with the bodies' spin about the normal and is carried
// into a tilted tangent plane with its magnitude.
TEST(ContactKernel, HistoryFollowsTheContactFrame) {
  LinearParams p{.kn = 1e6, .ks = 1e6, .mu = 10.0};
  ContactKinematics<3> k = restingContact(1e-6, 1e-3, 1e-3);
  Eigen::Vector3d fs(0.0, 0.5, 0.0);
  const double dt = 1e-4, spin = 10.0;
  k.spin_n = spin;  // 1e-3 rad per step about x
  ContactDissipation d;
  for (int s = 0; s < 100; ++s) contactForce<3, LinearLaw, false>(p, k, fs, dt, d);
  const double angle = spin * dt * 100;
  EXPECT_NEAR(fs.norm(), 0.5, 1e-12);
  EXPECT_NEAR(std::atan2(fs.z(), fs.y()), angle, 1e-4);
  // Tilt the normal by 0.1 rad about z: the force leaves the old plane with its magnitude.
  k.spin_n = 0.0;
  k.n = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d::UnitX();
  contactForce<3, LinearLaw, false>(p, k, fs, dt, d);
  EXPECT_NEAR(fs.dot(k.n), 0.0, 1e-14);
  EXPECT_NEAR(fs.norm(), 0.5, 1e-12);
}

TEST(ContactKernel, TwoDimensionalShearAndTorqueSign) {
  LinearParams p{.kn = 1e6, .ks = 1e6, .mu = 0.5};
  ContactKinematics<2> k;
  k.n = Eigen::Vector2d::UnitX();
  k.overlap = 1e-6;
  k.vc = {0.0, 0.1};
  k.spin_n = 0.0;
  k.shape = pairShape<2>(1e-3, 1e-3, 1.0);
  k.mstar = 1e-3;
  Eigen::Vector2d fs = Eigen::Vector2d::Zero();
  ContactDissipation d;
  const auto r = contactForce<2, LinearLaw, false>(p, k, fs, 1e-6, d);
  EXPECT_NEAR(r.force.y(), -0.1, 1e-15);   // -ks vt dt
  EXPECT_NEAR(r.n_cross_ft, -0.1, 1e-15);  // n x ft, out of plane
}

}  // namespace
}  // namespace rocklab
