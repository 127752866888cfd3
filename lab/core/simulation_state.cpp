// Simulation: state I/O. One serializer, visit(), names every field of the state; clones,
// checkpoints and the state hash are made from it or beside it, so a restart continues bit
// for bit and a layout change is refused rather than misread (archive.hpp).

#include "lab/core/simulation.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "lab/core/archive.hpp"
#include "lab/core/contact_laws.hpp"

namespace rocklab {

namespace {

constexpr char kMagic[8] = {'R', 'K', 'L', 'B', 'C', 'K', 'P', 'T'};
constexpr char kTrailer[8] = {'R', 'K', 'L', 'B', 'E', 'N', 'D', '!'};

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

template <class T>
std::uint64_t hashVector(const std::vector<T>& v, std::uint64_t h) {
  return v.empty() ? h : fnv1a(v.data(), v.size() * sizeof(T), h);
}

struct OverrideRow {
  std::uint16_t a = 0, b = 0;
  double friction = NAN, damping_ratio = NAN;  // NaN: not overridden
  template <class Archive>
  void visit(Archive& ar) {
    ar("a", a), ar("b", b), ar("friction", friction), ar("damping_ratio", damping_ratio);
  }
};

}  // namespace

template <int D>
Simulation<D> Simulation<D>::clone() const {
  ArchiveWriter w;
  const_cast<Simulation*>(this)->visit(w);
  Simulation copy(MaterialTable{}, SimulationConfig{});
  ArchiveReader r(w.bytes().data(), w.bytes().size());
  copy.visit(r);
  return copy;
}

template <int D>
std::string Simulation<D>::stateBytes() const {
  ArchiveWriter w;
  const_cast<Simulation*>(this)->visit(w);
  return w.bytes();
}

template <int D>
Simulation<D> Simulation<D>::fromStateBytes(const std::string& bytes) {
  Simulation s(MaterialTable{}, SimulationConfig{});
  ArchiveReader r(bytes.data(), bytes.size());
  s.visit(r);
  // The contact model is made from the configuration and materials, not stored: readouts
  // before the next step (the unbalanced force, the contacts) need it, as in the original.
  s.model_ = makeContactModel<D>(s.config_.contact_law, s.materials_);
  return s;
}

template <int D>
std::uint64_t Simulation<D>::stateHash() const {
  const auto& P = particles_;
  std::uint64_t h = 1469598103934665603ull;
  h = hashVector(P.pos, h);
  h = hashVector(P.vel, h);
  h = hashVector(P.spin, h);
  h = hashVector(P.force, h);
  h = hashVector(P.torque, h);
  h = hashVector(contacts_.shear, h);
  h = hashVector(contacts_.wall_shear, h);
  h = hashVector(clumps_.momentum, h);
  for (const BondLoad<D>& l : bonds_.load) {
    h = fnv1a(&l.fn, sizeof l.fn, h);
    h = fnv1a(l.fs.data(), sizeof(double) * D, h);
    if constexpr (D == 3) {
      h = fnv1a(l.mb.data(), sizeof(double) * 3, h);
      h = fnv1a(&l.mt, sizeof l.mt, h);
    } else {
      h = fnv1a(&l.mb, sizeof l.mb, h);
    }
  }
  for (const FaceState<D>& f : bonds_.face) {
    for (const FaceElement<D>& e : f.elements) {
      h = fnv1a(&e.bonded, sizeof e.bonded, h);
      h = fnv1a(&e.approach, sizeof e.approach, h);
      h = fnv1a(e.fs.data(), sizeof(double) * 2, h);
    }
  }
  for (const auto& w : walls_) {
    h = fnv1a(w.point.data(), sizeof(double) * D, h);
    h = fnv1a(w.velocity.data(), sizeof(double) * D, h);
    h = fnv1a(w.force.data(), sizeof(double) * D, h);
  }
  const double scalars[] = {time_,
                            dt_,
                            ledger_.boundary_work,
                            ledger_.body_work,
                            ledger_.friction,
                            ledger_.viscous,
                            ledger_.local_damping};
  return fnv1a(scalars, sizeof scalars, h);
}

template <int D>
template <class Archive>
void Simulation<D>::visit(Archive& ar) {
  ar("config.contact_law", config_.contact_law), ar("config.skin", config_.skin);
  ar("config.skin_ratio", config_.skin_ratio);
  ar("config.local_damping", config_.local_damping);
  ar("config.timestep.automatic", config_.timestep.automatic);
  ar("config.timestep.fixed_dt", config_.timestep.fixed_dt);
  ar("config.timestep.safety", config_.timestep.safety);
  ar("config.timestep.update_interval", config_.timestep.update_interval);
  ar("config.timestep.density_scaling", config_.timestep.density_scaling);
  ar("config.guard.overlap_limit", config_.guard.overlap_limit);
  ar("config.guard.energy_growth", config_.guard.energy_growth);
  ar("config.guard.energy_runaway", config_.guard.energy_runaway);
  ar("config.threads", config_.threads), ar("config.track_energy", config_.track_energy);
  ar("config.spatial_sort", config_.spatial_sort), ar("config.gravity", config_.gravity);
  ar("config.bond_breakage", config_.bond_breakage);

  std::vector<Material> mats = materials_.all();
  std::vector<OverrideRow> rows;
  for (const auto& [k, o] : materials_.overrides()) {
    rows.push_back({k.first, k.second, o.friction.value_or(NAN), o.damping_ratio.value_or(NAN)});
  }
  ar("materials", mats), ar("material_overrides", rows);
  if constexpr (Archive::kReading) {
    materials_ = MaterialTable{};
    for (auto& m : mats) materials_.add(std::move(m));
    for (const auto& r : rows) {
      PairOverride o;
      if (!std::isnan(r.friction)) o.friction = r.friction;
      if (!std::isnan(r.damping_ratio)) o.damping_ratio = r.damping_ratio;
      materials_.setPair(r.a, r.b, o);
    }
  }

  particles_.visit(ar);
  ar("walls", walls_), ar("wall_prev_force", wall_prev_force_);
  contacts_.visit(ar);
  rng_.visit(ar);
  ar("ledger.initial", ledger_.initial), ar("ledger.boundary_work", ledger_.boundary_work);
  ar("ledger.body_work", ledger_.body_work), ar("ledger.friction", ledger_.friction);
  ar("ledger.viscous", ledger_.viscous), ar("ledger.local_damping", ledger_.local_damping);
  ar("ledger.positive_input", ledger_.positive_input), ar("ledger.started", ledger_.started);
  ar("ledger.bond_breakage", ledger_.bond_breakage);
  ar("ledger.clump_release", ledger_.clump_release),
      ar("ledger.mass_scaling", ledger_.mass_scaling);
  clumps_.visit(ar);
  ar("clump_breaks", clump_breaks_);
  ar("bond_kinds", bond_kinds_), ar("bonds", bonds_), ar("bond_breaks", bond_breaks_);
  ar("broken_counts", broken_counts_);
  ar("time", time_), ar("dt", dt_), ar("step", step_), ar("kinetic", kinetic_);
  ar("forces_valid", forces_valid_);
  ar("damp_force", damp_force_), ar("damp_torque", damp_torque_);
  ar("applied", applied_);
}

template <int D>
void Simulation<D>::saveCheckpoint(const std::string& path) const {
  ArchiveWriter w;
  const_cast<Simulation*>(this)->visit(w);
  std::string file(kMagic, sizeof kMagic);
  const std::uint32_t version = kCheckpointVersion, dim = D;
  file.append(reinterpret_cast<const char*>(&version), sizeof version);
  file.append(reinterpret_cast<const char*>(&dim), sizeof dim);
  file += w.bytes();
  const std::uint64_t sum = fnv1a(file.data(), file.size());
  file.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  file.append(kTrailer, sizeof kTrailer);
  // Write beside the target and rename: a crash never leaves a half-written checkpoint.
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw CheckpointError("cannot write checkpoint '" + tmp + "'");
    out.write(file.data(), static_cast<std::streamsize>(file.size()));
    if (!out) throw CheckpointError("writing checkpoint '" + tmp + "' failed");
  }
  std::filesystem::rename(tmp, path);
}

template <int D>
Simulation<D> Simulation<D>::loadCheckpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CheckpointError("cannot open checkpoint '" + path + "'");
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t head = sizeof kMagic + 8, tail = 8 + sizeof kTrailer;
  if (file.size() < sizeof kMagic || std::memcmp(file.data(), kMagic, sizeof kMagic) != 0) {
    throw CheckpointError("'" + path + "' is not a rocklab checkpoint");
  }
  if (file.size() < head + tail ||
      std::memcmp(file.data() + file.size() - sizeof kTrailer, kTrailer, sizeof kTrailer) != 0) {
    throw CheckpointError("checkpoint '" + path + "' is truncated (its end marker is missing)");
  }
  std::uint32_t version, dim;
  std::memcpy(&version, file.data() + sizeof kMagic, 4);
  std::memcpy(&dim, file.data() + sizeof kMagic + 4, 4);
  if (version != kCheckpointVersion) {
    throw CheckpointError("checkpoint '" + path + "' has format version " +
                          std::to_string(version) + "; this rocklab reads version " +
                          std::to_string(kCheckpointVersion) +
                          " only: resume it with the rocklab that wrote it");
  }
  if (dim != D) {
    throw CheckpointError("checkpoint '" + path + "' holds a " + std::to_string(dim) +
                          "D scene, not " + std::to_string(D) + "D");
  }
  std::uint64_t sum;
  std::memcpy(&sum, file.data() + file.size() - tail, sizeof sum);
  if (fnv1a(file.data(), file.size() - tail) != sum) {
    throw CheckpointError("checkpoint '" + path + "' is damaged (checksum mismatch)");
  }
  Simulation sim(MaterialTable{}, SimulationConfig{});
  ArchiveReader r(file.data() + head, file.size() - head - tail);
  sim.visit(r);
  if (!r.atEnd()) throw CheckpointError("checkpoint '" + path + "' has trailing data");
  return sim;
}

#define ROCKLAB_STATE(D)                                                    \
  template Simulation<D> Simulation<D>::clone() const;                      \
  template std::string Simulation<D>::stateBytes() const;                   \
  template Simulation<D> Simulation<D>::fromStateBytes(const std::string&); \
  template std::uint64_t Simulation<D>::stateHash() const;                  \
  template void Simulation<D>::saveCheckpoint(const std::string&) const;    \
  template Simulation<D> Simulation<D>::loadCheckpoint(const std::string&);
ROCKLAB_STATE(2)
ROCKLAB_STATE(3)
#undef ROCKLAB_STATE

}  // namespace rocklab
