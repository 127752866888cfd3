#include "lab/core/bond_forces.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <type_traits>

#include "lab/core/bond_lanes.hpp"
#include "lab/core/contact_model.hpp"
#include "lab/core/errors.hpp"

namespace rocklab {

BondKind BondKind::grains() {
  BondKind k;
  k.name = "grain";
  k.intragranular = true;
  k.modulus = 8.0 * kGPa;
  k.stiffness_ratio = 1.0;
  k.tensile_mean = k.shear_mean = 40.0 * kMPa;
  k.tensile_std = k.shear_std = 0.0;
  k.negative = NegativeStrength::Resample;
  return k;
}

void BondKind::validate() const {
  if (model == BondModel::FlatJoint && moment_factor != 1.0) {
    throw InvalidParameter("", "moment_factor",
                           "applies to parallel bonds only: a flat joint's elements break on "
                           "their centroid stresses (leave it at 1 with model = flat_joint)");
  }
  if (model != BondModel::FlatJoint && flat_joint_slit_fraction != 0.0) {
    throw InvalidParameter("", "flat_joint_slit_fraction",
                           "applies to flat joints only: set model = flat_joint, or leave it at 0");
  }
  if (negative == NegativeStrength::Resample && (tensile_mean <= 0.0 || shear_mean <= 0.0)) {
    throw InvalidParameter("", "negative_strength",
                           "resample needs positive mean strengths (it draws until positive)");
  }
}

template <int D>
void BondStore<D>::removeFlagged(const std::vector<std::uint8_t>& broken) {
  std::size_t out = 0;
  for (std::size_t b = 0; b < size(); ++b) {
    if (broken[b]) continue;
    if (out != b) {
      i[out] = i[b], j[out] = j[b], kind[out] = kind[b], radius[out] = radius[b];
      kn[out] = kn[b], ks[out] = ks[b], tensile[out] = tensile[b], shear[out] = shear[b];
      load[out] = load[b], face[out] = std::move(face[b]);
    }
    ++out;
  }
  i.resize(out), j.resize(out), kind.resize(out), radius.resize(out), kn.resize(out);
  ks.resize(out), tensile.resize(out), shear.resize(out), load.resize(out);
  face.resize(out);
}

int bondLaneWidth(int requested) {
  if (requested >= 8 && lanes::wide()) return 8;
  if (requested >= 4 && lanes::available()) return 4;
  return 0;
}

template <int D>
void BondForces<D>::buildAdjacency(std::size_t particles, const BondStore<D>& bonds) {
  adjacency_row_.assign(particles + 1, 0);
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    ++adjacency_row_[bonds.i[b] + 1];
    ++adjacency_row_[bonds.j[b] + 1];
  }
  for (std::size_t k = 0; k < particles; ++k) adjacency_row_[k + 1] += adjacency_row_[k];
  adjacency_.resize(2 * bonds.size());
  std::vector<std::uint32_t> fill(adjacency_row_.begin(), adjacency_row_.end() - 1);
  for (std::uint32_t b = 0; b < bonds.size(); ++b) {
    adjacency_[fill[bonds.i[b]]++] = b << 1;
    adjacency_[fill[bonds.j[b]]++] = b << 1 | 1u;
  }
  adjacency_valid_ = true;
}

template <int D>
void BondForces<D>::compute(BondPass<D>& pass) {
  auto& P = pass.particles;
  auto& B = pass.bonds;
  const std::size_t nb = B.size();
  const std::size_t blocks = (nb + kBlockRows - 1) / kBlockRows;
  const double dt = pass.dt;
  block_.assign(blocks, {});
  if (pass.threaded) {
    active_.resize(nb);
    force_.resize(nb);
    torque_i_.resize(nb);
    torque_j_.resize(nb);
    if (!adjacency_valid_) buildAdjacency(P.size(), B);
  }

  if (tracking_ && !peaks_lost_ && peaks_.tensile.size() != nb) {
    if (peaks_.tensile.empty()) {
      peaks_.tensile.assign(nb, -std::numeric_limits<double>::infinity());
      peaks_.cohesion.assign(nb, -std::numeric_limits<double>::infinity());
    } else {
      peaks_lost_ = true;  // a bond was added or removed: the peaks name other bonds now
    }
  }
  const bool tracking = tracking_ && !peaks_lost_;
  tan_friction_.clear();
  moment_factor_.clear();
  joint_friction_.clear();
  layouts_.clear();
  bool frictional = false, moments_scaled = false;
  if (pass.kinds) {
    for (const BondKind& k : *pass.kinds) {
      tan_friction_.push_back(std::tan(k.friction_angle));
      moment_factor_.push_back(k.moment_factor);
      joint_friction_.push_back(k.flat_joint_friction);
      layouts_.push_back(k.model == BondModel::FlatJoint ? k.template faceLayout<D>()
                                                         : FaceLayout{});
      frictional = frictional || (k.friction_angle > 0.0 && k.model == BondModel::Parallel);
      moments_scaled = moments_scaled || k.moment_factor != 1.0;
    }
  }
  // The peak stresses with the moments' share scaled (BondKind::moment_factor), from the
  // load either path stored, in bondForce's order; with every factor 1 those of the pass
  // stand (the lanes' or bondForce's, the same bits).
  auto scaledStresses = [&](std::size_t b, const BondSection<D>& s, double& tensile,
                            double& shear) {
    const BondLoad<D>& l = B.load[b];
    const double beta = moment_factor_[B.kind[b]];
    if constexpr (D == 3) {
      shear = l.fs.norm() / s.area + beta * std::abs(l.mt) * s.radius / s.polar;
    } else {
      shear = l.fs.norm() / s.area;
    }
    tensile = -l.fn / s.area + beta * angNorm(l.mb) * s.radius / s.inertia;
  };
  // The shear strength c + sigma_n tan(phi) under a compressive normal stress sigma_n
  // (BondKind::friction_angle); the bond's load is this step's, stored by either path.
  auto frictionalStrength = [&](std::size_t b, const BondSection<D>& s) {
    const double sigma_n = B.load[b].fn / s.area;
    return sigma_n > 0.0 ? B.shear[b] + sigma_n * tan_friction_[B.kind[b]] : B.shear[b];
  };

  // A bond's force and torques go to its particles (threaded: to its slots).
  auto apply = [&](std::size_t b, const Vec<D>& force, const Ang<D>& ti, const Ang<D>& tj)
      __attribute__((always_inline)) {
    const std::uint32_t i = B.i[b], j = B.j[b];
    if (pass.threaded) {
      active_[b] = 1;
      force_[b] = force;
      torque_i_[b] = ti;
      torque_j_[b] = tj;
    } else {
      P.force[i] -= force;
      P.force[j] += force;
      P.torque[i] -= ti;  // ti is subtracted from i
      P.torque[j] += tj;
    }
  };
  // A parallel bond's outcome, the same from either path: at or past its strength it breaks
  // now and carries nothing more (the larger ratio of stress to strength names the mode when
  // both are reached); else its force and torques are applied.
  auto settle = [&](std::size_t blk, std::size_t b, const Vec<D>& force, const Ang<D>& ti,
                    const Ang<D>& tj, double tensile_stress, double shear_stress)
      __attribute__((always_inline)) {
    double shear_strength = B.shear[b];
    if ((pass.breakable || tracking) && (moments_scaled || frictional)) {  // breaks need them
      const auto section = BondSection<D>::of(B.radius[b], P.thickness);
      if (moments_scaled) scaledStresses(b, section, tensile_stress, shear_stress);
      if (frictional) shear_strength = frictionalStrength(b, section);
    }
    if (tracking) {  // each bond is settled by one thread: no race
      peaks_.tensile[b] = std::max(peaks_.tensile[b], tensile_stress);
      peaks_.cohesion[b] =
          std::max(peaks_.cohesion[b], shear_stress - (shear_strength - B.shear[b]));
    }
    if (pass.breakable && (tensile_stress >= B.tensile[b] || shear_stress >= shear_strength)) {
      const double rt = tensile_stress / B.tensile[b], rs = shear_stress / shear_strength;
      const bool tensile =
          tensile_stress >= B.tensile[b] && (shear_stress < shear_strength || rt >= rs);
      block_[blk].breaks.push_back(
          {static_cast<std::uint32_t>(b), tensile ? BondBreakMode::Tensile : BondBreakMode::Shear,
           tensile ? tensile_stress : shear_stress, 0.0, Vec<D>::Zero(), true});
      if (pass.threaded) active_[b] = 0;
      return;
    }
    apply(b, force, ti, tj);
  };
  // Bond b's kinematics at its contact point, with the lever arms li, lj (gaps and overlaps
  // shared halfway).
  auto kinematics = [&](std::size_t b, double& li, double& lj) {
    const std::uint32_t i = B.i[b], j = B.j[b];
    const Vec<D> d = P.pos[j] - P.pos[i];
    const double dist = d.norm();
    BondKinematics<D> k;
    k.n = d / dist;
    const double overlap = P.radius[i] + P.radius[j] - dist;  // < 0: a gap
    li = P.radius[i] - 0.5 * overlap, lj = P.radius[j] - 0.5 * overlap;
    k.vc = P.vel[j] - P.vel[i] - cross(Ang<D>(lj * P.spin[j] + li * P.spin[i]), k.n);
    k.dspin = P.spin[j] - P.spin[i];
    if constexpr (D == 3) {
      k.spin_n = 0.5 * spinAbout(Ang<D>(P.spin[i] + P.spin[j]), k.n);
    } else {
      k.spin_n = 0.0;
    }
    return k;
  };
  auto one = [&](std::size_t blk, std::size_t b) {
    double li, lj;
    const BondKinematics<D> k = kinematics(b, li, lj);
    const auto section = BondSection<D>::of(B.radius[b], P.thickness);
    const BondResult<D> r = bondForce<D>(section, B.kn[b], B.ks[b], k, B.load[b], dt);
    const Ang<D> ncf = cross(k.n, B.load[b].fs);
    settle(blk, b, r.force, li * ncf + r.moment, r.moment - lj * ncf, r.tensile, r.shear);
  };
  auto joint = [&](std::size_t blk, std::size_t b) {
    double li, lj;
    const BondKinematics<D> k = kinematics(b, li, lj);
    const std::uint8_t kind = B.kind[b];
    FaceMaterial m;
    m.radius = B.radius[b], m.thickness = P.thickness, m.kn = B.kn[b], m.ks = B.ks[b];
    m.tensile = B.tensile[b], m.cohesion = B.shear[b];
    m.tan_friction_angle = tan_friction_[kind], m.friction = joint_friction_[kind];
    m.breakable = pass.breakable;
    std::vector<ElementBreak<D>> element_breaks;  // allocates only when one breaks
    const FaceResult<D> r = flatJointStep<D>(layouts_[kind], m, k.n, k.vc, k.dspin, k.spin_n,
                                             B.face[b], dt, element_breaks);
    BlockOut& out = block_[blk];
    for (const ElementBreak<D>& e : element_breaks) {
      out.breaks.push_back({static_cast<std::uint32_t>(b),
                            e.tensile ? BondBreakMode::Tensile : BondBreakMode::Shear, e.stress,
                            e.energy, e.offset, false});
    }
    out.slip_energy += r.slip_energy;
    if (r.released) out.released.push_back(static_cast<std::uint32_t>(b));
    const Ang<D> ncf = cross(k.n, r.shear);
    apply(b, r.force, li * ncf + r.moment, r.moment - lj * ncf);
  };
  auto scalar = [&](std::size_t blk, std::size_t b) {
    if (B.face[b].empty()) {
      one(blk, b);
    } else {
      joint(blk, b);
    }
  };

  // W parallel bonds at a time (lanes::avx or lanes::avx512). Each group is settled after
  // the next one is computed: its results are ready by then, and its scalar scatter overlaps
  // the tail of the next group's chain. W flat joints of one kind (3D) go through the lanes
  // of their own, and are recorded and applied at once, in bond order; a group of other mixes
  // goes a bond at a time on the scalar path. Returns the first bond left (the block's last
  // few).
  const auto inLanes = [&]<class Settled, class Joints, class Compute, class ComputeJoints>(
                           std::size_t blk, std::size_t b, std::size_t end, Compute&& compute,
                           ComputeJoints&& computeJoints) {
    constexpr int W = sizeof(Settled::tensile) / sizeof(double);
    Settled s[2];
    int slot = 0;
    std::size_t pending = end;  // the group computed but not yet settled
    auto settleGroup = [&](std::size_t first, const Settled& r) {
      for (int k = 0; k < W; ++k) {
        if constexpr (D == 3) {
          settle(blk, first + k, Vec<3>(r.force[0][k], r.force[1][k], r.force[2][k]),
                 Ang<3>(r.ti[0][k], r.ti[1][k], r.ti[2][k]),
                 Ang<3>(r.tj[0][k], r.tj[1][k], r.tj[2][k]), r.tensile[k], r.shear[k]);
        } else {
          settle(blk, first + k, Vec<2>(r.force[0][k], r.force[1][k]), r.ti[k], r.tj[k],
                 r.tensile[k], r.shear[k]);
        }
      }
    };
    auto flush = [&] {
      if (pending != end) settleGroup(pending, s[slot ^ 1]);
      pending = end;
    };
    // W flat joints of one kind: the joints' lanes where the dimension has them.
    auto jointsOfOneKind = [&](std::size_t first) {
      if (B.face[first].empty()) return false;
      for (int k = 1; k < W; ++k) {
        if (B.face[first + k].empty() || B.kind[first + k] != B.kind[first]) return false;
      }
      return true;
    };
    Joints joints;
    while (b + W <= end) {
      bool plain = true;
      for (int k = 0; k < W; ++k) plain &= B.face[b + k].empty();
      if (plain) {
        compute(b, s[slot]);
        if (pending != end) settleGroup(pending, s[slot ^ 1]);
        pending = b;
        slot ^= 1;
        b += W;
        continue;
      }
      flush();  // in bond order: the breaks of a block stay sorted
      if constexpr (D == 3) {
        if (jointsOfOneKind(b)) {
          computeJoints(b, joints);
          BlockOut& out = block_[blk];
          for (int k = 0; k < W; ++k) {
            for (const ElementBreak<3>& e : joints.breaks[k]) {
              out.breaks.push_back({static_cast<std::uint32_t>(b + k),
                                    e.tensile ? BondBreakMode::Tensile : BondBreakMode::Shear,
                                    e.stress, e.energy, e.offset, false});
            }
            joints.breaks[k].clear();
            out.slip_energy += joints.slip_energy[k];
            if ((joints.released >> k) & 1) {
              out.released.push_back(static_cast<std::uint32_t>(b + k));
            }
            apply(b + k, Vec<3>(joints.force[0][k], joints.force[1][k], joints.force[2][k]),
                  Ang<3>(joints.ti[0][k], joints.ti[1][k], joints.ti[2][k]),
                  Ang<3>(joints.tj[0][k], joints.tj[1][k], joints.tj[2][k]));
          }
          b += W;
          continue;
        }
      }
      scalar(blk, b++);
    }
    flush();
    return b;
  };
  const int width = bondLaneWidth(pass.lane_width);
  const bool breakable = pass.breakable;
  // Bonds [b, end) of block blk through the lanes of one width (K: its Kernels).
  const auto byWidth = [&]<class K>(std::size_t blk, std::size_t b, std::size_t end) {
    using Settled = std::conditional_t<D == 3, typename K::Settled3, typename K::Settled2D>;
    using Joints = typename K::JointsOut;
    return inLanes.template operator()<Settled, Joints>(
        blk, b, end, [&](std::size_t first, Settled& s) { K::parallel(P, B, first, dt, s); },
        [&](std::size_t first, Joints& j) {
          if constexpr (D == 3) {
            const std::uint8_t kind = B.kind[first];
            K::flatJoints(P, B, first, dt, layouts_[kind], tan_friction_[kind],
                          joint_friction_[kind], breakable, j);
          }
        });
  };

#pragma omp parallel for schedule(dynamic, 1) num_threads(pass.threads) if (pass.threaded)
  for (std::size_t blk = 0; blk < blocks; ++blk) {
    const std::size_t end = std::min(nb, (blk + 1) * kBlockRows);
    std::size_t b = blk * kBlockRows;
    if (width == 8) b = byWidth.template operator()<lanes::avx512::Kernels>(blk, b, end);
    if (width == 4) b = byWidth.template operator()<lanes::avx::Kernels>(blk, b, end);
    for (; b < end; ++b) scalar(blk, b);  // no lanes, or the block's last few bonds
  }

  if (pass.threaded) {
#pragma omp parallel for schedule(static) num_threads(pass.threads)
    for (std::size_t p = 0; p < P.size(); ++p) {
      Vec<D> f = P.force[p];
      Ang<D> t = P.torque[p];
      for (std::uint32_t q = adjacency_row_[p]; q < adjacency_row_[p + 1]; ++q) {
        const std::uint32_t b = adjacency_[q] >> 1;
        if (!active_[b]) continue;
        if (adjacency_[q] & 1u) {
          f += force_[b];
          t += torque_j_[b];
        } else {
          f -= force_[b];
          t -= torque_i_[b];
        }
      }
      P.force[p] = f;
      P.torque[p] = t;
    }
  }
  for (const BlockOut& out : block_) {
    for (const Break& k : out.breaks) {
      pass.broken.push_back(k.bond);
      pass.modes.push_back(k.mode);
      pass.stresses.push_back(k.stress);
      pass.removes.push_back(k.removes ? 1 : 0);
      pass.offsets.push_back(k.offset);
      pass.energies.push_back(k.energy);
    }
    pass.released.insert(pass.released.end(), out.released.begin(), out.released.end());
    pass.slip_energy += out.slip_energy;
  }
}

template struct BondStore<2>;
template struct BondStore<3>;
template class BondForces<2>;
template class BondForces<3>;

}  // namespace rocklab
