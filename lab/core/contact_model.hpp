#pragma once
// A contact law bound to a scene's materials: pair parameters mixed once into a table, and
// the force loops over particle pairs and particle-wall contacts, compiled per law.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lab/core/contact_kernels.hpp"
#include "lab/core/contacts.hpp"
#include "lab/core/material.hpp"
#include "lab/core/particles.hpp"
#include "lab/core/walls.hpp"

namespace rocklab {

// Rows per block of the force loop. Per-block partial sums are added in block order, so
// energy and guard totals do not depend on the number of threads.
inline constexpr std::size_t kBlockRows = 256;

// Everything one force pass reads and writes.
template <int D>
struct ContactPass {
  ParticleStore<D>& particles;
  ContactStore<D>& contacts;
  std::vector<Wall<D>>& walls;
  double dt;
  bool threaded;  // split the particles among `threads` (same bits as one thread)
  int threads;
  bool track_energy;
  double overlap_limit;  // overlap / smaller radius beyond which the guard trips
  int lane_width;        // touching pairs up to this many per vector register (8, 4; 0: one at a
                         // time) where the law and the CPU can: the same bits at any width

  // Out: energy dissipated in contacts this step (J), and whether an overlap exceeded the
  // limit.
  double friction = 0.0;
  double viscous = 0.0;
  bool overlap_exceeded = false;
};

// One pair's force on j and torques (lever arm times n x F_t) on i and on j.
template <int D>
struct PairForce {
  Vec<D> force;
  Ang<D> torque_i, torque_j;
};

// A contact's result kept where another thread or a later serial sum must apply it in the
// serial order. `diss` holds what the contact alone dissipated, so adding it to a running
// total gives the same bits as the serial accumulation.
template <int D>
struct KeptContact {
  PairForce<D> f;
  ContactDissipation diss;
  double kn = 0.0, cn = 0.0;  // wall contacts: what the wall's servo gain reads
  bool touching = false;
};

// Work space of the force loops, kept between steps to avoid reallocating.
template <int D>
struct PairBuffers {
  std::vector<std::size_t> range;                     // rows of each thread: [range[t], range[t+1])
  std::vector<std::vector<std::uint32_t>> own_cross;  // per thread, its rows' cross pairs
  std::vector<std::vector<std::uint32_t>> own_cross_row;
  std::vector<std::uint32_t> cross, cross_row;  // all cross pairs (ascending) and their rows
  std::vector<std::size_t> cross_start;         // where each thread's cross pairs start in `cross`
  std::vector<std::uint32_t> cross_index;       // a cross pair's place in `cross`, by pair
  std::vector<KeptContact<D>> cross_result, wall_result;
  std::vector<std::size_t> wall_split;
  std::vector<double> block_friction, block_viscous, block_cost;
  std::vector<std::uint32_t> block_touching;  // touching pairs per block, last threaded step
  // Each thread's pace in its rows (split cost per second), smoothed over the steps, and the
  // seconds of its rows in the last step: the split follows the pace of the core each thread
  // ran on (threadedPairLoop).
  std::vector<double> thread_pace, thread_seconds;
  std::vector<std::uint8_t> block_over, thread_over;
};

template <int D>
class ContactModel {
 public:
  virtual ~ContactModel() = default;
  virtual std::string_view law() const = 0;
  // Pair and wall forces of one step, added to the particles' forces and torques.
  virtual void computeForces(ContactPass<D>& pass) = 0;
  // The rows each thread took in the last threaded pass, [rows[t], rows[t + 1]) (whole
  // blocks of kBlockRows but the last run's end); empty before one. The per-particle passes
  // take the same runs, so a particle stays on the core that computed its forces.
  virtual const std::vector<std::size_t>& threadRows() const = 0;
  // Tangent normal and shear stiffness (N/m) of a contact at an overlap.
  virtual std::pair<double, double> stiffness(std::uint16_t mi, std::uint16_t mj, double overlap,
                                              const ContactShape& g, double mstar) const = 0;
  // Elastic normal force (N) of a contact at an overlap.
  virtual double normalForce(std::uint16_t mi, std::uint16_t mj, double overlap,
                             const ContactShape& g) const = 0;
  // Elastic energy stored in a contact (J).
  virtual double strainEnergy(std::uint16_t mi, std::uint16_t mj, double overlap,
                              const ContactShape& g, double mstar, double shear_force2) const = 0;
  // Critical step (s) of a particle that touches nothing yet: it bounds the step before
  // contacts form (linear: sqrt(m / kn) of a contact with its own kind, `self` the shape of
  // that contact; Hertz: the Rayleigh wave time across the particle).
  virtual double freeParticleStep(std::uint16_t material, const ContactShape& self, double radius,
                                  double mass, double inertia, double density) const = 0;
};

// Pair parameters of every material pair, mixed once.
template <class Params>
class PairTable {
 public:
  PairTable() = default;
  template <class Mix>
  PairTable(const MaterialTable& m, Mix mix) : n_(m.size()), p_(n_ * n_) {
    for (std::size_t a = 0; a < n_; ++a) {
      for (std::size_t b = 0; b < n_; ++b) {
        p_[a * n_ + b] = mix(m, static_cast<std::uint16_t>(a), static_cast<std::uint16_t>(b));
      }
    }
  }
  const Params& operator()(std::uint16_t a, std::uint16_t b) const { return p_[a * n_ + b]; }

 private:
  std::size_t n_ = 0;
  std::vector<Params> p_;
};

template <int D, class Law>
std::unique_ptr<ContactModel<D>> bindContactLaw(std::string_view name,
                                                PairTable<typename Law::Params> table,
                                                std::vector<Material> materials);

}  // namespace rocklab
