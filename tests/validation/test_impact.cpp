// Binary impacts against closed-form results: Hertz (Johnson 1985, ch. 11), the linear
// spring-dashpot oscillator, and the restitution its damping ratio implies.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/support.hpp"

namespace rocklab {
namespace {

using testing::addParticle;
using V3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

struct Impact {
  double duration = 0.0;     // s, first to last step with overlap
  double max_overlap = 0.0;  // m
  double restitution = 0.0;  // - separation speed / approach speed
};

// Runs a head-on impact until the bodies separate. `overlap` reads the current overlap,
// `speed` the relative normal speed (positive = approaching).
template <class Overlap, class Speed>
Impact measure(Simulation<3>& sim, Overlap overlap, Speed speed, double dt) {
  Impact r;
  const double v0 = speed();
  std::uint64_t first = 0, last = 0;
  bool touched = false;
  for (int s = 0; s < 10000000; ++s) {
    sim.step();
    const double o = overlap();
    if (o > 0.0) {
      if (!touched) first = sim.steps();
      touched = true;
      last = sim.steps();
      r.max_overlap = std::max(r.max_overlap, o);
    } else if (touched) {
      break;
    }
  }
  // Contact spans the steps first..last: count (last - first + 1) steps of dt each.
  r.duration = static_cast<double>(last - first + 1) * dt;
  r.restitution = -speed() / v0;
  return r;
}

// Integral of (1 - x^(5/2))^(-1/2) over [0, 1]: the shape factor of the Hertz impact time.
double hertzTimeFactor() {
  const double a = 2.5;
  return std::tgamma(1 / a) * std::tgamma(0.5) / (a * std::tgamma(1 / a + 0.5));
}

constexpr double kE = 70e9, kNu = 0.25, kRho = 2650, kR = 1e-3;

Simulation<3> hertzScene(double dt, double damping_ratio = 0.0) {
  SimulationConfig cfg = testing::undamped();
  cfg.contact_law = "hertz";
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = dt;
  return Simulation<3>(testing::table(testing::hertzMaterial(kE, kNu, 0.0, damping_ratio, kRho)),
                       cfg);
}

TEST(HertzImpact, SphereSphereDurationAndOverlap) {
  const double v0 = 0.2;
  const double m = kRho * 4.0 / 3.0 * kPi * kR * kR * kR;
  const double mstar = m / 2, rstar = kR / 2, estar = kE / (2 * (1 - kNu * kNu));
  const double dmax = std::pow(15 * mstar * v0 * v0 / (16 * estar * std::sqrt(rstar)), 0.4);
  const double tc = 2 * hertzTimeFactor() * dmax / v0;
  const double dt = tc / 4000;
  Simulation<3> sim = hertzScene(dt);
  const auto a = addParticle<3>(sim, V3(0, 0, 0), kR, V3(v0 / 2, 0, 0));
  const auto b = addParticle<3>(sim, V3(2 * kR + 1e-7, 0, 0), kR, V3(-v0 / 2, 0, 0));
  auto& P = sim.particles();
  const Impact r = measure(
      sim, [&] { return 2 * kR - (P.pos[P.index(b)] - P.pos[P.index(a)]).norm(); },
      [&] { return (P.vel[P.index(a)] - P.vel[P.index(b)]).x(); }, dt);
  EXPECT_NEAR(r.duration / tc, 1.0, 0.01);
  EXPECT_NEAR(r.max_overlap / dmax, 1.0, 0.01);
  EXPECT_NEAR(r.restitution, 1.0, 1e-3);  // elastic
}

TEST(HertzImpact, SphereWallDurationAndOverlap) {
  const double v0 = 0.5;
  const double m = kRho * 4.0 / 3.0 * kPi * kR * kR * kR;
  const double estar = kE / (2 * (1 - kNu * kNu));  // the wall has the same elastic constants
  const double dmax = std::pow(15 * m * v0 * v0 / (16 * estar * std::sqrt(kR)), 0.4);
  const double tc = 2 * hertzTimeFactor() * dmax / v0;
  const double dt = tc / 4000;
  Simulation<3> sim = hertzScene(dt);
  const auto a = addParticle<3>(sim, V3(0, 0, kR + 1e-7), kR, V3(0, 0, -v0));
  Wall<3> floor;
  floor.normal = V3::UnitZ();
  sim.addWall(floor);
  auto& P = sim.particles();
  const Impact r = measure(
      sim, [&] { return kR - P.pos[P.index(a)].z(); }, [&] { return -P.vel[P.index(a)].z(); }, dt);
  EXPECT_NEAR(r.duration / tc, 1.0, 0.01);
  EXPECT_NEAR(r.max_overlap / dmax, 1.0, 0.01);
}

Simulation<3> linearScene(double kn, double beta, double dt) {
  SimulationConfig cfg = testing::undamped();
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = dt;
  return Simulation<3>(testing::table(testing::linearMaterial(kn, 0.0, 0.0, beta, kRho)), cfg);
}

TEST(LinearImpact, DurationIsHalfThePeriod) {
  const double kn = 2e6, v0 = 0.1;  // contact stiffness kn / 2 (two springs in series)
  const double m = kRho * 4.0 / 3.0 * kPi * kR * kR * kR, mstar = m / 2;
  const double tc = kPi * std::sqrt(mstar / (kn / 2));
  const double dt = tc / 2000;
  Simulation<3> sim = linearScene(kn, 0.0, dt);
  const auto a = addParticle<3>(sim, V3(0, 0, 0), kR, V3(v0 / 2, 0, 0));
  const auto b = addParticle<3>(sim, V3(2 * kR + 1e-8, 0, 0), kR, V3(-v0 / 2, 0, 0));
  auto& P = sim.particles();
  const Impact r = measure(
      sim, [&] { return 2 * kR - (P.pos[P.index(b)] - P.pos[P.index(a)]).norm(); },
      [&] { return (P.vel[P.index(a)] - P.vel[P.index(b)]).x(); }, dt);
  EXPECT_NEAR(r.duration / tc, 1.0, 0.005);
  EXPECT_NEAR(r.max_overlap, v0 * std::sqrt(mstar / (kn / 2)), 1e-3 * r.max_overlap);
}

// A linear spring-dashpot with damping ratio beta restitutes e = exp(-pi beta / sqrt(1 -
// beta^2)) over a contact lasting pi / (omega sqrt(1 - beta^2)).
TEST(LinearImpact, RestitutionFromDampingRatio) {
  for (double beta : {0.05, 0.2, 0.5}) {
    const double kn = 2e6, v0 = 0.1;
    const double m = kRho * 4.0 / 3.0 * kPi * kR * kR * kR, mstar = m / 2;
    const double omega = std::sqrt((kn / 2) / mstar);
    const double tc = kPi / (omega * std::sqrt(1 - beta * beta));
    const double dt = tc / 4000;
    Simulation<3> sim = linearScene(kn, beta, dt);
    const auto a = addParticle<3>(sim, V3(0, 0, 0), kR, V3(v0 / 2, 0, 0));
    const auto b = addParticle<3>(sim, V3(2 * kR + 1e-8, 0, 0), kR, V3(-v0 / 2, 0, 0));
    auto& P = sim.particles();
    const Impact r = measure(
        sim, [&] { return 2 * kR - (P.pos[P.index(b)] - P.pos[P.index(a)]).norm(); },
        [&] { return (P.vel[P.index(a)] - P.vel[P.index(b)]).x(); }, dt);
    const double e = std::exp(-kPi * beta / std::sqrt(1 - beta * beta));
    EXPECT_NEAR(r.restitution / e, 1.0, 0.01) << "beta " << beta;
    EXPECT_NEAR(r.duration / tc, 1.0, 0.005) << "beta " << beta;
  }
}

// Reference for a Hertz impact with Tsuji's dashpot, m x'' = -K x^1.5 - c0 x^0.25 x', by
// a fine fourth-order Runge-Kutta integration: the restitution it implies.
double tsujiRestitution(double mstar, double rstar, double estar, double beta, double v0) {
  const double K = 4.0 / 3.0 * estar * std::sqrt(rstar);
  const double c0 =
      2 * std::sqrt(5.0 / 6.0) * beta * std::sqrt(2 * estar * std::sqrt(rstar) * mstar);
  auto acc = [&](double x, double v) {
    if (x <= 0) return 0.0;
    return (-K * std::pow(x, 1.5) - c0 * std::pow(x, 0.25) * v) / mstar;
  };
  double x = 0, v = v0;
  const double dmax = std::pow(15 * mstar * v0 * v0 / (16 * estar * std::sqrt(rstar)), 0.4);
  const double h = dmax / v0 / 20000;
  do {
    const double k1x = v, k1v = acc(x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = acc(x + h * k3x, v + h * k3v);
    x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  } while (x > 0);
  return -v / v0;
}

TEST(HertzImpact, TsujiDampingRestitutionIsSpeedIndependentAndMatchesTheOde) {
  const double beta = 0.2;
  const double m = kRho * 4.0 / 3.0 * kPi * kR * kR * kR;
  const double estar = kE / (2 * (1 - kNu * kNu));
  std::vector<double> measured;
  for (double v0 : {0.05, 0.5, 2.0}) {
    const double dmax = std::pow(15 * (m / 2) * v0 * v0 / (16 * estar * std::sqrt(kR / 2)), 0.4);
    const double dt = 2 * hertzTimeFactor() * dmax / v0 / 4000;
    Simulation<3> sim = hertzScene(dt, beta);
    const auto a = addParticle<3>(sim, V3(0, 0, 0), kR, V3(v0 / 2, 0, 0));
    const auto b = addParticle<3>(sim, V3(2 * kR + 1e-9, 0, 0), kR, V3(-v0 / 2, 0, 0));
    auto& P = sim.particles();
    const Impact r = measure(
        sim, [&] { return 2 * kR - (P.pos[P.index(b)] - P.pos[P.index(a)]).norm(); },
        [&] { return (P.vel[P.index(a)] - P.vel[P.index(b)]).x(); }, dt);
    const double reference = tsujiRestitution(m / 2, kR / 2, estar, beta, v0);
    EXPECT_NEAR(r.restitution / reference, 1.0, 0.005) << "v0 " << v0;
    measured.push_back(r.restitution);
  }
  EXPECT_NEAR(measured.front() / measured.back(), 1.0, 0.01);
}

}  // namespace
}  // namespace rocklab
