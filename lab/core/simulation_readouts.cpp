// Simulation: what observers read (energy, coordination, the unbalanced force, the critical
// time step, contact forces, stage timings) and the instability guard, which stops a run at
// the step it went wrong with a diagnosis naming the likely cause.

#include "lab/core/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "lab/core/simulation_touching.hpp"

namespace rocklab {

namespace {

// The sum of the norms of a per-particle vector over the free particles (clump pebbles left
// out) and of a per-clump one over the live clumps, and how many bodies that is.
template <class Particles, class Clumps, class PerParticle, class PerClump>
std::pair<double, std::size_t> freeBodyNorms(const Particles& P, const Clumps& K,
                                             const PerParticle& of_particle,
                                             const PerClump& of_clump) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    sum += of_particle[i].norm();
    ++count;
  }
  for (std::size_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    sum += of_clump[c].norm();
    ++count;
  }
  return {sum, count};
}

}  // namespace

template <int D>
void Simulation<D>::guard(bool overlap_exceeded) {
  if (!std::isfinite(kinetic_)) {
    fail(SimulationUnstable::Cause::NonFinite, "a particle velocity is no longer finite");
  }
  if (overlap_exceeded) {
    std::ostringstream s;
    s << "an overlap exceeded " << config_.guard.overlap_limit
      << " of the smaller radius (numerics.overlap_limit)";
    fail(SimulationUnstable::Cause::Overlap, s.str());
  }
  // Kinetic energy cannot exceed what the sample held plus what was put in; a few times
  // more means the integration itself is creating energy.
  const double budget = ledger_.initial + ledger_.positive_input;
  if (config_.guard.energy_runaway && kinetic_ > config_.guard.energy_growth * budget &&
      kinetic_ > 1e-300) {
    std::ostringstream s;
    s << "kinetic energy " << kinetic_ << " J exceeds " << config_.guard.energy_growth
      << " times the energy put into the sample (" << budget << " J)";
    fail(SimulationUnstable::Cause::EnergyRunaway, s.str());
  }
}

template <int D>
void Simulation<D>::fail(SimulationUnstable::Cause cause, const std::string& what) const {
  std::ostringstream s;
  s << "the run became unstable at step " << step_ << " (t = " << time_ << " s): " << what << ".\n"
    << diagnose();
  throw SimulationUnstable(cause, step_, s.str());
}

template <int D>
std::string Simulation<D>::diagnose() const {
  const auto& P = particles_;
  std::ostringstream s;
  s.precision(3);
  double rmin = INFINITY;
  for (double r : P.radius) rmin = std::min(rmin, r);
  int causes = 0;

  const double scaling = config_.timestep.density_scaling;
  if (scaling > 1.0 && config_.timestep.automatic) {
    // Scaled masses put every scaled particle's own bound at the step over the safety factor
    // (automaticStep): the estimate of the physical masses says nothing then, and a stiffening
    // between two estimates (contacts closing fast, a stiffer material) takes the scaled
    // particles past their bound together.
    ++causes;
    s << "Likely cause: density scaling (numerics.density_scaling = " << scaling
      << ") steps each scaled particle at its own stability bound times the safety factor ("
      << config_.timestep.safety
      << "), so a stiffening between two estimates of the step takes them past it together. "
         "Lower numerics.density_scaling or numerics.timestep_safety.\n";
  } else if (const double crit = criticalTimeStep(); std::isfinite(crit) && dt_ > crit) {
    ++causes;
    s << "Likely cause: the time step " << dt_ << " s is above the critical estimate " << crit
      << " s (particle mass and contact stiffness); use automatic stepping or lower the "
         "fixed step or the safety factor.\n";
  }
  for (const auto& w : walls_) {
    const double per_step = w.velocity.norm() * dt_;
    if (per_step > 0.01 * rmin) {
      ++causes;
      s << "Likely cause: wall '" << w.name << "' moves " << 100.0 * per_step / rmin
        << "% of the smallest radius per step (" << w.velocity.norm()
        << " m/s); lower its velocity or servo max_speed.\n";
    }
  }
  double vmax = 0.0;
  std::size_t fastest = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double v = P.vel[i].norm();
    if (!(v <= vmax)) vmax = v, fastest = i;
  }
  if (!std::isfinite(vmax) || vmax * dt_ > 0.05 * rmin) {
    ++causes;
    s << "Particle " << P.slot_of[fastest] << " at (" << P.pos[fastest].transpose() << ") moves "
      << vmax * dt_ / rmin << " smallest radii per step.\n";
  }
  if (causes == 0) {
    s << "No single cause stands out: check the stiffness contrast between materials, the "
         "loading rate and numerics.overlap_limit.\n";
  }
  // The deepest contact as it stands: where to look, and how fast it closed.
  Touching deepest;
  double ratio = 0.0;
  forEachTouching([&](const Touching& t) {
    if (t.overlap / t.min_radius > ratio) ratio = t.overlap / t.min_radius, deepest = t;
  });
  if (ratio > 0.0) {
    const std::size_t i = deepest.i, j = deepest.j;
    const Vec<D> n =
        deepest.wall ? Vec<D>(-deepest.wall->normal) : Vec<D>((P.pos[j] - P.pos[i]).normalized());
    const Vec<D> vj = deepest.wall ? deepest.wall->velocity : P.vel[j];
    const double closing = (P.vel[i] - vj).dot(n);
    s << "Deepest contact: particle " << P.slot_of[i] << " (radius " << P.radius[i] << " m, at ("
      << P.pos[i].transpose() << ")) and ";
    if (deepest.wall) {
      s << "wall '" << deepest.wall->name << "'";
    } else {
      s << "particle " << P.slot_of[j] << " (radius " << P.radius[j] << " m)";
    }
    const double per_step = closing * dt_ / deepest.min_radius;
    s << ": overlap " << ratio << " of the smaller radius, closing at " << closing << " m/s ("
      << per_step << " of that radius per step).\n";
    // A contact that closed slowly carries a load too high for its stiffness: the model's
    // limit, not the integration's.
    if (ratio >= config_.guard.overlap_limit && std::abs(per_step) < 1e-4) {
      s << "It closed slowly: a static load too high for the contact stiffness, not an "
           "instability. Stiffen the contacts, or raise numerics.overlap_limit if an overlap this "
           "deep is acceptable for the smallest particles.\n";
    }
  }
  return s.str();
}

template <int D>
typename Simulation<D>::StepLimits Simulation<D>::stepLimits() const {
  const auto& P = particles_;
  const std::size_t n = P.size();
  if (!model_) throw std::logic_error("criticalTimeStep() before the simulation is prepared");
  std::vector<double> kt(n, 0.0), kr(n, 0.0);
  forEachTouching([&](const Touching& t) {
    const auto [kn, ks] = model_->stiffness(t.mi, t.mj, t.overlap, t.shape, t.mstar);
    kt[t.i] += kn;
    kr[t.i] += ks * t.li * t.li;
    if (!t.wall) {
      kt[t.j] += kn;
      kr[t.j] += ks * t.lj * t.lj;
    }
  });
  // Bonds add their normal stiffness to translation, shear and bending to rotation.
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    const auto s = BondSection<D>::of(bonds_.radius[b], P.thickness);
    const double kn = bonds_.kn[b] * s.area, ks = bonds_.ks[b] * s.area;
    const double moment = bonds_.kn[b] * s.inertia + bonds_.ks[b] * s.polar;
    for (const std::uint32_t p : {bonds_.i[b], bonds_.j[b]}) {
      kt[p] += kn;
      kr[p] += ks * P.radius[p] * P.radius[p] + moment;
    }
  }
  StepLimits limits;
  double& dt = limits.bodies;
  // A clump's pebbles act in parallel on the body: their stiffnesses add up, the rotational
  // ones with the arm from the centroid (bounded by distance plus radius).
  const auto& K = clumps_;
  for (std::uint32_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    double kt_body = 0.0, kr_body = 0.0;
    const double density = K.mass[c] / K.volume[c];
    for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
      const std::size_t i = P.indexOfSlot(K.member_slot[k]);
      const double arm = (P.pos[i] - K.pos[c]).norm() + P.radius[i];
      kt_body += kt[i];
      kr_body += kr[i] + kt[i] * arm * arm;
      // A pebble meeting something new moves at most its own mass (conservative bound).
      const double m = density * P.volume(i);
      dt = std::min(dt, model_->freeParticleStep(
                            P.material[i], pairShape<D>(P.radius[i], P.radius[i], P.thickness),
                            P.radius[i], m, particleInertia<D>(m, P.radius[i]), density));
    }
    double imin = 0.0;
    if constexpr (D == 2) {
      imin = K.principal[c];
    } else {
      imin = K.principal[c].minCoeff();
    }
    if (kt_body > 0.0) dt = std::min(dt, std::sqrt(K.mass[c] / kt_body));
    if (kr_body > 0.0) dt = std::min(dt, std::sqrt(imin / kr_body));
  }
  limits.particle.assign(n, INFINITY);
  for (std::size_t i = 0; i < n; ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    const double m = 1.0 / P.physical_inv_mass[i], inertia = 1.0 / P.physical_inv_inertia[i];
    double& own = limits.particle[i];
    own =
        model_->freeParticleStep(P.material[i], pairShape<D>(P.radius[i], P.radius[i], P.thickness),
                                 P.radius[i], m, inertia, m / P.volume(i));
    if (kt[i] > 0.0) own = std::min(own, std::sqrt(m / kt[i]));
    if (kr[i] > 0.0) own = std::min(own, std::sqrt(inertia / kr[i]));
  }
  return limits;
}

template <int D>
double Simulation<D>::criticalTimeStep() const {
  const StepLimits limits = stepLimits();
  double dt = limits.bodies;
  for (const double own : limits.particle) dt = std::min(dt, own);
  return dt;
}

template <int D>
double Simulation<D>::inertialMassRatio() const {
  const auto& P = particles_;
  double inertial = 0.0, physical = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    inertial += 1.0 / P.inv_mass[i];
    physical += 1.0 / P.physical_inv_mass[i];
  }
  return physical > 0.0 ? inertial / physical : 1.0;
}

template <int D>
EnergyReport Simulation<D>::energy() const {
  const auto& P = particles_;
  EnergyReport e;
  e.ledger = ledger_;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    e.kinetic_translation += 0.5 * P.vel[i].squaredNorm() / P.inv_mass[i];
    e.kinetic_rotation += 0.5 * angDot(P.spin[i], P.spin[i]) / P.inv_inertia[i];
  }
  const auto& K = clumps_;
  for (std::size_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    e.kinetic_translation += 0.5 * K.mass[c] * K.vel[c].squaredNorm();
    e.kinetic_rotation += rotationalEnergy(K.spin[c], K.momentum[c]);
  }
  if (!model_) return e;
  forEachTouching([&](const Touching& t) {
    e.strain += model_->strainEnergy(t.mi, t.mj, t.overlap, t.shape, t.mstar, t.shear2);
  });
  std::vector<FaceLayout> layouts;
  for (const BondKind& k : bond_kinds_) layouts.push_back(k.template faceLayout<D>());
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    if (bonds_.face[b].empty()) {
      const auto s = BondSection<D>::of(bonds_.radius[b], P.thickness);
      e.strain += bondEnergy<D>(s, bonds_.kn[b], bonds_.ks[b], bonds_.load[b]);
      continue;
    }
    FaceMaterial m;
    m.radius = bonds_.radius[b], m.thickness = P.thickness;
    m.kn = bonds_.kn[b], m.ks = bonds_.ks[b];
    e.strain += faceEnergy<D>(layouts[bonds_.kind[b]], m, bonds_.face[b]);
  }
  return e;
}

template <int D>
std::size_t Simulation<D>::particleContacts() const {
  std::size_t count = 0;
  forEachTouching([&](const Touching& t) { count += t.wall == nullptr; });
  return count;
}

template <int D>
double Simulation<D>::maxOverlapRatio() const {
  double worst = 0.0;
  forEachTouching([&](const Touching& t) { worst = std::max(worst, t.overlap / t.min_radius); });
  return worst;
}

template <int D>
std::vector<typename Simulation<D>::ContactForce> Simulation<D>::contactForces() const {
  std::vector<ContactForce> out;
  if (!model_) return out;
  forEachTouching([&](const Touching& t) {
    if (t.wall) return;
    out.push_back(
        {t.i, t.j, model_->normalForce(t.mi, t.mj, t.overlap, t.shape), std::sqrt(t.shear2)});
  });
  return out;
}

template <int D>
double Simulation<D>::coordinationNumber() const {
  return particles_.size() ? 2.0 * static_cast<double>(particleContacts()) /
                                 static_cast<double>(particles_.size())
                           : 0.0;
}

template <int D>
double Simulation<D>::unbalancedForceRatio() const {
  const auto& P = particles_;
  if (!model_) return 0.0;
  const auto [unbalanced, free] = freeBodyNorms(P, clumps_, P.force, clumps_.force);
  double contact = 0.0;
  std::size_t count = 0;
  forEachTouching([&](const Touching& t) {
    if (t.wall) return;
    const double fn = model_->normalForce(t.mi, t.mj, t.overlap, t.shape);
    contact += std::sqrt(fn * fn + t.shear2);
    ++count;
  });
  if (count == 0 || free == 0) return 0.0;
  return (unbalanced / static_cast<double>(free)) / (contact / static_cast<double>(count));
}

template <int D>
double Simulation<D>::meanSpeed() const {
  const auto [sum, free] = freeBodyNorms(particles_, clumps_, particles_.vel, clumps_.vel);
  return free ? sum / static_cast<double>(free) : 0.0;
}

template <int D>
typename Simulation<D>::V Simulation<D>::unbalancedForceMoment(const V& origin) const {
  const auto& P = particles_;
  V g;
  for (int d = 0; d < D; ++d) g[d] = config_.gravity[d];
  const auto applied = [&](std::size_t i) {
    const std::uint32_t slot = P.slot_of[i];
    return slot < applied_.size() ? applied_[slot] : V(V::Zero());
  };
  V moment = V::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;  // clumps: whole bodies
    const V f = P.force[i] - g / P.physical_inv_mass[i] - applied(i);
    moment += V((P.pos[i] - origin).array() * f.array());
  }
  const auto& K = clumps_;
  for (std::uint32_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    V f = K.force[c] - K.mass[c] * g;
    for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
      f -= applied(P.indexOfSlot(K.member_slot[k]));
    }
    moment += V((K.pos[c] - origin).array() * f.array());
  }
  return moment;
}

template <int D>
std::vector<StageTiming> Simulation<D>::stageTimings() const {
  static constexpr const char* kNames[kStages] = {
      "integrate", "neighbors", "body_forces", "contacts", "bonds", "wall_servo", "guard"};
  std::vector<StageTiming> out;
  for (int s = 0; s < kStages; ++s) {
    if (stages_[s].calls == 0) continue;  // a stage the scene does not call for never ran
    out.push_back({kNames[s], stages_[s].seconds, stages_[s].calls});
  }
  return out;
}

#define ROCKLAB_READOUTS(D)                                                               \
  template void Simulation<D>::guard(bool);                                               \
  template void Simulation<D>::fail(SimulationUnstable::Cause, const std::string&) const; \
  template std::string Simulation<D>::diagnose() const;                                   \
  template double Simulation<D>::criticalTimeStep() const;                                \
  template double Simulation<D>::inertialMassRatio() const;                               \
  template typename Simulation<D>::StepLimits Simulation<D>::stepLimits() const;          \
  template EnergyReport Simulation<D>::energy() const;                                    \
  template std::size_t Simulation<D>::particleContacts() const;                           \
  template double Simulation<D>::maxOverlapRatio() const;                                 \
  template std::vector<Simulation<D>::ContactForce> Simulation<D>::contactForces() const; \
  template double Simulation<D>::coordinationNumber() const;                              \
  template double Simulation<D>::unbalancedForceRatio() const;                            \
  template Vec<D> Simulation<D>::unbalancedForceMoment(const Vec<D>&) const;              \
  template double Simulation<D>::meanSpeed() const;                                       \
  template std::vector<StageTiming> Simulation<D>::stageTimings() const;
ROCKLAB_READOUTS(2)
ROCKLAB_READOUTS(3)
#undef ROCKLAB_READOUTS

}  // namespace rocklab
