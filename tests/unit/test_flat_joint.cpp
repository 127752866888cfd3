// The flat-jointed bond (Potyondy 2012; flat_joint.hpp) against hand calculations: the face's
// elements tile it and add up to its section, an intact face is the parallel bond of the
// same section in every mode, each element breaks at its strength on its centroid's stress,
// a partly broken face still bends with the stiffness of its bonded elements, broken
// elements carry compression and friction but no tension, and the four-lane and threaded bond
// passes give the same bits with flat joints among the bonds.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lab/core/errors.hpp"
#include "lab/core/random.hpp"
#include "tests/bonded_pair.hpp"

namespace rocklab {
namespace {

using namespace testing::bonded;
constexpr double kPi = std::numbers::pi;

BondKind joint(double tensile, double cohesion, int radial, int circumferential = 1) {
  BondKind k = cement(tensile, cohesion);
  k.model = BondModel::FlatJoint;
  k.flat_joint_radial = radial;
  k.flat_joint_circumferential = circumferential;
  return k;
}

// Sums over the elements: area, first moments and second moments about the face's centre
// (parallel axis theorem: an element's own about its centroid plus A times the arm squared).
struct FaceSums {
  double area = 0, x = 0, y = 0, xx = 0, yy = 0, xy = 0;
  explicit FaceSums(const FaceLayout& L) {
    for (const FaceElementShape& e : L.elements) {
      area += e.area, x += e.area * e.x, y += e.area * e.y;
      xx += e.ixx + e.area * e.x * e.x;
      yy += e.iyy + e.area * e.y * e.y;
      xy += e.ixy + e.area * e.x * e.y;
    }
  }
};

TEST(FlatJointFace, ElementsTileTheFaceAndAddUpToItsSection) {
  for (int n : {1, 2, 3, 5}) {  // 2D: a face 2 long (radius 1): area 2, I = 2 / 3
    const FaceSums s(FaceLayout::of2D(n));
    EXPECT_NEAR(s.area, 2.0, 1e-14) << n;
    EXPECT_NEAR(s.x, 0.0, 1e-14) << n;
    EXPECT_NEAR(s.xx, 2.0 / 3.0, 1e-14) << n;
  }
  for (auto [rings, sectors] : {std::pair{1, 1}, {1, 3}, {2, 4}, {3, 5}}) {
    // 3D: a disk of radius 1: area pi, I = pi / 4 about any diameter, no product moment.
    const FaceSums s(FaceLayout::of3D(rings, sectors));
    EXPECT_NEAR(s.area, kPi, 1e-13) << rings << "x" << sectors;
    EXPECT_NEAR(s.x, 0.0, 1e-13);
    EXPECT_NEAR(s.y, 0.0, 1e-13);
    EXPECT_NEAR(s.xx, kPi / 4, 1e-13) << rings << "x" << sectors;
    EXPECT_NEAR(s.yy, kPi / 4, 1e-13) << rings << "x" << sectors;
    EXPECT_NEAR(s.xy, 0.0, 1e-13) << rings << "x" << sectors;
  }
  // One ring of three sectors: sector 0 spans 0..120 deg, its centroid at 60 deg and
  // 2 sin(60) / (3 pi / 3) = sqrt(3) / pi from the centre, its area pi / 3.
  const FaceLayout three = FaceLayout::of3D(1, 3);
  EXPECT_NEAR(three.elements[0].area, kPi / 3, 1e-15);
  EXPECT_NEAR(std::hypot(three.elements[0].x, three.elements[0].y), std::sqrt(3.0) / kPi, 1e-15);
  EXPECT_NEAR(std::atan2(three.elements[0].y, three.elements[0].x), kPi / 3, 1e-14);
  // Seen from the other particle: 2D the order reverses; 3D each ring's angles turn over.
  const FaceLayout four = FaceLayout::of2D(4);
  EXPECT_EQ(four.mirror(0), 3u);
  EXPECT_EQ(four.mirror(1), 2u);
  const FaceLayout rings = FaceLayout::of3D(2, 3);
  EXPECT_EQ(rings.mirror(0), 2u);
  EXPECT_EQ(rings.mirror(1), 1u);
  EXPECT_EQ(rings.mirror(3), 5u);
  EXPECT_NEAR(rings.elements[rings.mirror(4)].y, -rings.elements[4].y, 1e-15);
}

// Intact, a flat joint is the parallel bond of its section in every mode (the formulas of
// test_bonds.cpp's BondStiffness tests): its elements' stiffnesses add up to the face's.
TEST(FlatJointStiffness, AnIntactFaceIsTheParallelBondIn3D) {
  const double v = 0.01, w = 10.0;
  const auto kind = joint(1e11, 1e11, 2, 3);
  {
    BondedPair<3> p(kind);
    p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 100);
    EXPECT_NEAR(p.force().x(), -p.kn() * p.section().area * 100 * v * kDt, 1e-9 * p.force().norm());
    EXPECT_NEAR(p.force().y(), 0.0, 1e-9 * p.force().norm());
  }
  {
    BondedPair<3> p(kind);
    p.drive(V3::Zero(), V3(0, v, 0), V3::Zero(), V3::Zero(), 100);
    EXPECT_NEAR(p.force().y(), -p.ks() * p.section().area * 100 * v * kDt, 1e-3 * p.force().norm());
  }
  for (int axis : {1, 2}) {  // bending about y and z: the face is isotropic
    BondedPair<3> p(kind);
    const V3 spin = w * V3::Unit(axis);
    p.drive(V3::Zero(), V3::Zero(), -spin, spin, 100);
    const double theta = 2 * w * 100 * kDt;
    EXPECT_NEAR(p.torque()[axis], -p.kn() * p.section().inertia * theta, 1e-9 * p.torque().norm());
    EXPECT_LT(p.force().norm(), 1e-9 * p.torque().norm() / kR);
  }
  {
    BondedPair<3> p(kind);
    p.drive(V3::Zero(), V3::Zero(), V3(-w, 0, 0), V3(w, 0, 0), 100);
    EXPECT_NEAR(p.torque().x(), -p.ks() * p.section().polar * 2 * w * 100 * kDt,
                1e-9 * p.torque().norm());
  }
}

TEST(FlatJointStiffness, AnIntactFaceIsTheParallelBondIn2D) {
  const double v = 0.01, w = 10.0;
  const auto kind = joint(1e11, 1e11, 3);
  {
    BondedPair<2> p(kind);
    p.drive(V2::Zero(), V2(v, 0), 0.0, 0.0, 100);
    EXPECT_NEAR(p.force().x(), -p.kn() * 2 * kR * 100 * v * kDt, 1e-9 * p.force().norm());
  }
  {
    BondedPair<2> p(kind);
    p.drive(V2::Zero(), V2(0, v), 0.0, 0.0, 100);
    EXPECT_NEAR(p.force().y(), -p.ks() * 2 * kR * 100 * v * kDt, 1e-3 * p.force().norm());
  }
  {
    BondedPair<2> p(kind);
    p.drive(V2::Zero(), V2::Zero(), -w, w, 100);
    const double inertia = 2 * kR * kR * kR / 3;
    EXPECT_NEAR(p.torque(), -p.kn() * inertia * 2 * w * 100 * kDt, 1e-9 * std::abs(p.torque()));
  }
}

// Pulled apart, every element carries -Fn / A = kn * stretch and all break in the step that
// reaches the tensile strength; broken and apart, the face goes and nothing holds the pair.
TEST(FlatJointBreaks, InTensionEveryElementBreaksAtTheStrengthAndTheFaceGoes) {
  const double strength = 8e6, v = 0.01;
  BondedPair<3> p(joint(strength, 1e11, 2, 3));
  const double per_step = p.kn() * v * kDt;
  int steps = 0;
  while (p.sim.bondBreaks().empty() && steps < 100000) {
    p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 1);
    ++steps;
  }
  EXPECT_NEAR(steps, std::ceil(strength / per_step), 1);  // rounding may take one more
  ASSERT_EQ(p.sim.bondBreaks().size(), 6u);
  const double stretch = steps * v * kDt;
  for (const auto& b : p.sim.bondBreaks()) {
    EXPECT_EQ(b.mode, BondBreakMode::Tensile);
    EXPECT_GE(b.stress, strength);
    EXPECT_LT(b.stress, strength + 1.0001 * per_step);
    EXPECT_NEAR(b.position.x(), kR + (kGap + stretch) / 2, 1e-12);  // on the face
  }
  EXPECT_EQ(p.sim.brokenBonds(0, BondBreakMode::Tensile), 6u);
  EXPECT_EQ(p.sim.bonds().size(), 0u);
  p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 1);
  EXPECT_EQ(p.force().norm(), 0.0);
}

// 2D, two elements with centroids at -R/2 and +R/2. Bent by theta, the element on the
// stretched side carries kn theta R / 2: it breaks at theta = 2 sigma_t / (kn R), twice the
// rotation that breaks the parallel bond (peripheral stress kn theta R). The face then still
// bends, by its bonded element alone: kn (A x^2 + I_e) = kn (R^3 / 4 + R^3 / 12) t, half the
// intact face's 2 R^3 t / 3. Bent back, the broken element closes and carries compression.
TEST(FlatJointBreaks, APartlyBrokenFaceStillBendsWithItsBondedElements) {
  const double strength = 8e6, w = 10.0;
  BondedPair<2> p(joint(strength, 1e11, 2));
  const double per_step = p.kn() * (kR / 2) * 2 * w * kDt;
  int steps = 0;
  while (p.sim.bondBreaks().empty() && steps < 100000) {
    p.drive(V2::Zero(), V2::Zero(), -w, w, 1);
    ++steps;
  }
  EXPECT_NEAR(steps, std::ceil(strength / per_step), 1);
  ASSERT_EQ(p.sim.bondBreaks().size(), 1u);
  const auto& b = p.sim.bondBreaks()[0];
  EXPECT_EQ(b.mode, BondBreakMode::Tensile);
  EXPECT_GE(b.stress, strength);
  EXPECT_LT(b.stress, strength + 1.0001 * per_step);
  // j turns anticlockwise: the gap opens below the line of centres (the face's -R/2).
  EXPECT_NEAR(b.position.y(), -kR / 2, 1e-12);
  ASSERT_EQ(p.sim.bonds().size(), 1u);
  EXPECT_TRUE(p.sim.bonds().intact(0));
  EXPECT_FALSE(p.sim.bonds().face[0].elements[0].bonded);

  const double before = p.torque();
  p.drive(V2::Zero(), V2::Zero(), -w, w, 10);
  const double bonded_element = kR * kR * kR / 4 + kR * kR * kR / 12;  // t = 1
  EXPECT_NEAR(p.torque() - before, -p.kn() * bonded_element * 2 * w * 10 * kDt,
              1e-9 * std::abs(p.torque()));
  EXPECT_EQ(p.sim.bondBreaks().size(), 1u);

  // Back past the unbent state: the broken element's surfaces meet again at theta = its
  // stretch at the break, then it pushes (compression), never pulls.
  FaceElement<2> broken = p.sim.bonds().face[0].elements[0];
  EXPECT_LT(broken.approach, 0.0);
  p.drive(V2::Zero(), V2::Zero(), w, -w, steps + 10 + 20);
  broken = p.sim.bonds().face[0].elements[0];
  EXPECT_GT(broken.approach, 0.0);
  const FaceElement<2>& bonded = p.sim.bonds().face[0].elements[1];
  EXPECT_TRUE(bonded.bonded);
  // Now both elements push back against the reversed bend: the torque on j is positive and
  // is the bonded element's kn (A x^2 + I_e) theta plus the broken one's kn A approach R / 2.
  const double theta = -20 * 2 * w * kDt;  // net rotation of j relative to i
  const double expected = -p.kn() * bonded_element * theta + p.kn() * kR * broken.approach * kR / 2;
  EXPECT_GT(p.torque(), 0.0);
  EXPECT_NEAR(p.torque(), expected, 1e-6 * std::abs(expected));
}

// Sheared under a compressive normal stress sigma = kn * approach, a bonded element breaks at
// c + sigma tan(phi), and under tension at c - |sigma| tan(phi) (PFC's flat joint: tension
// lowers the shear strength). Broken, the face slides: its shear force is mu times its normal
// force; pulled apart, it goes without another break.
TEST(FlatJointBreaks, InShearAtCohesionPlusFrictionThenTheBrokenFaceSlides) {
  const double c = 2e6, phi = 40.0 * kPi / 180.0, mu = 0.5, v = 0.01;
  for (const double approach : {0.5e-6, -0.2e-6}) {
    BondKind kind = joint(1e11, c, 2);
    kind.friction_angle = phi;
    kind.flat_joint_friction = mu;
    BondedPair<2> p(kind);
    const int load_steps = 1000;
    p.drive(V2::Zero(), -approach / (load_steps * kDt) * p.n, 0.0, 0.0, load_steps);
    const double sigma = p.kn() * approach;
    const double strength = c + sigma * std::tan(phi);
    std::size_t steps = 0;
    while (p.sim.bondBreaks().empty() && steps < 100000) {
      p.drive(V2::Zero(), V2(0, v), 0.0, 0.0, 1);
      ++steps;
    }
    ASSERT_EQ(p.sim.bondBreaks().size(), 2u) << "approach " << approach;
    for (const auto& b : p.sim.bondBreaks()) {
      EXPECT_EQ(b.mode, BondBreakMode::Shear);
      // The normal turns as j slides (by 4e-4 rad here): sigma moves by about 200 Pa.
      EXPECT_GE(b.stress, strength * (1 - 5e-4));
      EXPECT_LT(b.stress, strength + 1.01 * p.ks() * v * kDt) << "approach " << approach;
    }
    if (approach < 0) {
      // Broken under tension: no normal force, so no friction either; the face is apart.
      EXPECT_EQ(p.sim.bonds().size(), 0u);
      continue;
    }
    ASSERT_EQ(p.sim.bonds().size(), 1u);
    EXPECT_FALSE(p.sim.bonds().intact(0));
    p.drive(V2::Zero(), V2(0, v), 0.0, 0.0, 50);
    const double fn = p.kn() * 2 * kR * approach;  // both elements, t = 1
    const V2 n = (p.P().pos[p.P().index(p.b)] - p.P().pos[p.P().index(p.a)]).normalized();
    const double normal = p.force().dot(n);
    EXPECT_NEAR(normal, fn, 1e-3 * fn);
    EXPECT_NEAR((p.force() - normal * n).norm(), mu * normal, 1e-9 * fn);
    // Pulled apart by twice the approach: the face goes, no break is logged for it.
    p.drive(V2::Zero(), 2 * approach / (100 * kDt) * p.n, 0.0, 0.0, 100);
    EXPECT_EQ(p.sim.bonds().size(), 0u);
    EXPECT_EQ(p.sim.bondBreaks().size(), 2u);
  }
}

// A face loaded in every mode (normal, shear, bending, twist) with one element broken, for the
// frame tests below: a few steps of a relative motion that is none of the axes'.
template <int D>
struct LoadedFace {
  FaceLayout layout = FaceLayout::of<D>(2, 3);
  FaceMaterial m;
  Vec<D> n;
  FaceState<D> f;
  std::vector<ElementBreak<D>> breaks;
  LoadedFace() {
    m.radius = kR, m.thickness = 2 * kR, m.kn = 1e13, m.ks = 4e12;
    m.tensile = m.cohesion = 1e11, m.tan_friction_angle = 0.5, m.friction = 0.5;
    if constexpr (D == 3) {
      n = V3(1, 2, 2) / 3;
    } else {
      n = V2(3, 4) / 5;
    }
    f = installFace<D>(layout, n);
    f.elements[1].bonded = 0;
    for (int s = 0; s < 20; ++s) step(motion(), spin(), 3.0);
  }
  static Vec<D> motion() {
    if constexpr (D == 3) {
      return V3(-0.02, 0.01, 0.004);
    } else {
      return V2(-0.02, 0.01);
    }
  }
  static Ang<D> spin() {
    if constexpr (D == 3) {
      return V3(3, -2, 5);
    } else {
      return 4.0;
    }
  }
  FaceResult<D> step(const Vec<D>& vc, const Ang<D>& dspin, double spin_n) {
    return flatJointStep<D>(layout, m, n, vc, dspin, spin_n, f, kDt, breaks);
  }
};

// Seen from the other particle (the bond store swaps a pair to keep i < j), a face's next
// step gives the opposite force, shear and moment about the face's centre: the normal turns
// over and the relative motion with it, and swapSides turns every element's components over
// into the other particle's frame.
template <int D>
void expectOppositeFromTheOtherSide() {
  LoadedFace<D> a;
  LoadedFace<D> b = a;
  b.f.swapSides(b.layout);
  b.n = -a.n;
  const FaceResult<D> ra = a.step(a.motion(), a.spin(), 3.0);
  const FaceResult<D> rb = b.step(-a.motion(), -a.spin(), -3.0);
  const double scale = ra.force.norm();
  ASSERT_GT(scale, 0.0);
  EXPECT_LT((rb.force + ra.force).norm(), 1e-12 * scale);
  EXPECT_LT((rb.shear + ra.shear).norm(), 1e-12 * scale);
  if constexpr (D == 3) {
    EXPECT_LT((rb.moment + ra.moment).norm(), 1e-12 * scale * kR);
  } else {
    EXPECT_LT(std::abs(rb.moment + ra.moment), 1e-12 * scale * kR);
  }
  EXPECT_NEAR(faceEnergy<D>(b.layout, b.m, b.f), faceEnergy<D>(a.layout, a.m, a.f),
              1e-12 * faceEnergy<D>(a.layout, a.m, a.f));
}

TEST(FlatJointFrame, SeenFromTheOtherParticleTheFaceGivesTheOppositeForceAndMoment) {
  expectOppositeFromTheOtherSide<2>();
  expectOppositeFromTheOtherSide<3>();
}

// Objectivity: a loaded face turned rigidly with its pair (no relative motion at the contact,
// the normal and the mean spin turning together) keeps its forces and moments, turned with
// it. A quarter turn about an axis oblique to the normal, in steps of 1e-4 rad, lands within
// 1e-3 of the turned load (the frame follows to first order per step).
TEST(FlatJointFrame, ARigidlyTurnedFaceKeepsItsLoadTurnedWithIt) {
  LoadedFace<3> face;
  const FaceResult<3> before = face.step(V3::Zero(), V3::Zero(), 0.0);
  const V3 axis = V3(2, -1, 1).normalized();
  const double per_step = 1e-4;
  const int steps = static_cast<int>(std::round(0.5 * kPi / per_step));
  const V3 omega = axis * per_step / kDt;
  for (int s = 0; s < steps; ++s) {
    face.n = Eigen::AngleAxisd(per_step, axis) * face.n;
    face.step(V3::Zero(), V3::Zero(), omega.dot(face.n));
  }
  const FaceResult<3> after = face.step(V3::Zero(), V3::Zero(), 0.0);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(steps * per_step, axis).toRotationMatrix();
  EXPECT_LT((after.force - turn * before.force).norm(), 1e-3 * before.force.norm());
  EXPECT_LT((after.moment - turn * before.moment).norm(), 1e-3 * before.moment.norm());
  EXPECT_NEAR(after.force.norm(), before.force.norm(), 1e-12 * before.force.norm());
  EXPECT_TRUE(face.breaks.empty());
}

// What a shaken sample of flat joints and parallel bonds ends in.
struct Outcome {
  std::vector<V3> pos;
  std::vector<double> stresses;
  double friction = 0.0, breakage = 0.0;  // J, the energy ledger's (joints' slip included)
  std::size_t faces = 0;                  // joints left (the released ones removed)
  std::uint64_t hash = 0;
};

// Flat joints among parallel bonds: the joints in lanes of their own, eight or four to a
// register (bond_lanes.inc), on one and two threads, give the bits of bonds one at a time on
// one thread. The joints (the first bonds installed, so groups of one kind) break in both
// modes, their broken elements slide, and some faces come apart and go.
TEST(FlatJointPass, LanesAndThreadsGiveTheSerialBitsWithJointsAmongTheBonds) {
  auto run = [](int width, int threads) {
    SimulationConfig cfg = testing::undamped();
    cfg.timestep.automatic = false;
    cfg.timestep.fixed_dt = kDt;
    cfg.bond_lane_width = width;
    cfg.threads = threads;
    Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), cfg);
    Rng rng(11);
    for (int x = 0; x < 7; ++x) {
      for (int y = 0; y < 5; ++y) {
        for (int z = 0; z < 4; ++z) {
          const V3 jitter(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
          testing::addParticle<3>(sim, V3(2 * kR * V3(x, y, z) + 0.02 * kR * jitter),
                                  kR * rng.uniform(0.98, 1.02), V3::Zero());
        }
      }
    }
    // Joints on the closest pairs, parallel bonds on the rest.
    const auto joints = sim.addBondKind(joint(2e6, 3e6, 2, 3));
    const std::size_t joint_count = sim.cement(joints, 0.01).installed;
    EXPECT_GT(joint_count, 20u);
    EXPECT_GT(sim.cement(sim.addBondKind(cement(2e6, 3e6)), 0.1).installed, 100u);
    auto& P = sim.particles();
    for (std::size_t i = 0; i < P.size(); ++i) {
      P.vel[i] = 0.05 * V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      P.spin[i] = 50 * V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    }
    for (int s = 0; s < 400; ++s) sim.step();
    Outcome o;
    for (const auto& b : sim.bondBreaks()) o.stresses.push_back(b.stress);
    for (std::size_t i = 0; i < P.size(); ++i) o.pos.push_back(P.pos[i]);
    const EnergyLedger& l = sim.energy().ledger;
    o.friction = l.friction, o.breakage = l.bond_breakage;
    for (const FaceState<3>& f : sim.bonds().face) o.faces += f.empty() ? 0 : 1;
    o.hash = sim.stateHash();
    EXPECT_GT(sim.brokenBonds(joints, BondBreakMode::Tensile), 0u);
    EXPECT_GT(sim.brokenBonds(joints, BondBreakMode::Shear), 0u);
    EXPECT_LT(o.faces, joint_count);  // some came apart
    return o;
  };
  const Outcome serial = run(0, 1);
  EXPECT_GT(serial.stresses.size(), 10u);
  EXPECT_GT(serial.friction, 0.0);
  for (const auto& [width, threads] : {std::pair{4, 1}, {8, 1}, {8, 2}}) {
    const Outcome fast = run(width, threads);
    SCOPED_TRACE(::testing::Message() << width << " lanes, " << threads << " threads");
    EXPECT_EQ(fast.stresses, serial.stresses);
    EXPECT_EQ(fast.pos, serial.pos);
    EXPECT_EQ(fast.friction, serial.friction);
    EXPECT_EQ(fast.breakage, serial.breakage);
    EXPECT_EQ(fast.faces, serial.faces);
    EXPECT_EQ(fast.hash, serial.hash);
  }
}

// Slit elements (PFC's fj_slit): each element of every face is installed unbonded with the
// slit fraction's probability, alone: over a lattice's faces their share is the fraction
// within the binomial's 4 standard deviations, and some faces hold both kinds.
TEST(FlatJointSlits, EachElementIsSlitWithTheFractionsProbability) {
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  for (int x = 0; x < 8; ++x) {
    for (int y = 0; y < 8; ++y) {
      for (int z = 0; z < 8; ++z) {
        testing::addParticle<3>(sim, V3(2 * kR * V3(x, y, z)), kR, V3::Zero());
      }
    }
  }
  BondKind k = joint(8e6, 8e6, 2, 3);
  k.flat_joint_slit_fraction = 0.4;
  EXPECT_EQ(sim.cement(sim.addBondKind(k), 0.01).installed, 3u * 8 * 8 * 7);
  double elements = 0, slit = 0;
  std::size_t mixed = 0;
  for (const FaceState<3>& f : sim.bonds().face) {
    std::size_t here = 0;
    for (const FaceElement<3>& e : f.elements) here += e.bonded ? 0 : 1;
    elements += static_cast<double>(f.elements.size());
    slit += static_cast<double>(here);
    mixed += here > 0 && here < f.elements.size() ? 1 : 0;
  }
  EXPECT_NEAR(slit / elements, 0.4, 4.0 * std::sqrt(0.4 * 0.6 / elements));
  EXPECT_GT(mixed, sim.bonds().size() / 2);
}

// A face with slits pulled apart: only its bonded elements hold tension, so it breaks at the
// tensile strength times their area (every element at the same approach in a pure pull), and
// its slit elements never break (no break event of theirs).
TEST(FlatJointSlits, APulledFaceHoldsTensionOnItsBondedElementsOnly) {
  const double strength = 8e6, v = 0.01;
  BondKind k = joint(strength, 1e11, 2, 3);
  k.flat_joint_slit_fraction = 0.5;
  BondedPair<3> p(k);
  const FaceLayout layout = k.faceLayout<3>();
  double bonded_area = 0;
  std::size_t bonded = 0;
  for (std::size_t e = 0; e < layout.elements.size(); ++e) {
    if (p.sim.bonds().face[0].elements[e].bonded) {
      bonded_area += layout.elements[e].area * kR * kR, ++bonded;  // the unit face's, at R
    }
  }
  ASSERT_GT(bonded, 0u) << "the seed slit every element: pick a face with some bonded";
  ASSERT_LT(bonded, layout.elements.size()) << "the seed slit none";
  double peak = 0;
  while (p.sim.bondBreaks().empty()) {
    p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 1);
    peak = std::max(peak, p.force().dot(-p.n));
  }
  const double per_step = p.kn() * v * kDt;
  EXPECT_NEAR(peak, strength * bonded_area, per_step * bonded_area);
  EXPECT_EQ(p.sim.bondBreaks().size(), bonded);
}

TEST(FlatJoint, KindsAreValidated) {
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  BondKind k = joint(8e6, 8e6, 2, 3);
  k.moment_factor = 0.5;  // applies to parallel bonds only
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
  k = joint(8e6, 8e6, 0, 3);
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
  k = cement(8e6, 8e6);
  k.flat_joint_slit_fraction = 0.2;  // a parallel bond has no elements to slit
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
}

}  // namespace
}  // namespace rocklab
