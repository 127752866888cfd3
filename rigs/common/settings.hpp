#pragma once
// The protocol sections every rig shares, each a settings struct that declares its fields
// once (lab/core/fields.hpp) beside the core's own (PackingSpec, BondKind, Material,
// SimulationConfig): `protocol.*`, `sample.*` with `grains.*` and `clumps.*`, `material.*`,
// `bonds.*`, `grain_bonds.*`, `formation.*`, `numerics.*` and `output.*`. A rig's own
// settings struct holds a SpecimenSettings and adds its sections (rigs/registry.hpp).

#include <cstdint>
#include <string>
#include <vector>

#include "lab/core/bonds.hpp"
#include "lab/core/grains.hpp"
#include "lab/core/packing.hpp"
#include "lab/core/simulation.hpp"
#include "lab/samples/sample_files.hpp"

namespace rocklab::rigs {

struct ProtocolInfo {
  std::string name;
  std::string rig;  // its choices are the rig table's (rigs/registry.cpp)
  std::string description;
  int dimension = 3;
  std::int64_t seed = 1;
  std::vector<std::string> key_results;

  template <class F>
  void fields(F& f) {
    f(name, {"name", units::text, {}, "name of the protocol, as it appears in the notebook", true});
    f(rig, {"rig", units::text, {}, "the rig that runs the protocol", true});
    f(description, {"description", units::text, {}, "what the protocol is for"});
    f(dimension, {"dimension", units::none, Range::closed(2, 3), "2 (disks) or 3 (spheres)"});
    f(seed,
      {"seed", units::none, Range::closed(0, 9e15), "seed of the packing and the bond strengths"});
    f(key_results, {"key_results",
                    units::text,
                    {},
                    "the protocol's key results, from its rig's list (`rocklab keys RIG`): what "
                    "reports headline, accuracy studies compare and regression references guard"});
  }
};

enum class SampleKind { Spheres, Grains, Clumps, File };
enum class LengthUnit { M, Cm, Mm, Um };
double metresPer(LengthUnit u);

// The sample: the packing (the core's PackingSpec, or a file the user brings), its box and,
// for grains, their shape.
struct SampleSettings {
  SampleKind kind = SampleKind::Spheres;
  PackingSpec packing = [] {
    PackingSpec p;
    p.count = 0;  // none: required unless the sample is read from a file (validate)
    return p;
  }();
  std::string file;  // sample.kind = file: the path, resolved against the protocol's folder
  SampleFormat format = SampleFormat::Auto;
  LengthUnit file_unit = LengthUnit::M;
  double aspect_axial = 1.0;        // -, the box's axial length over its lateral ones
  GrainShapeSpec grain_shape;       // sample.kind = grains or clumps
  double clump_break_stress = 0.0;  // Pa, sample.kind = clumps; 0: unbreakable

  template <class F>
  void fields(F& f) {
    static constexpr Choice<SampleKind> kKinds[] = {{"spheres", SampleKind::Spheres},
                                                    {"grains", SampleKind::Grains},
                                                    {"clumps", SampleKind::Clumps},
                                                    {"file", SampleKind::File}};
    static constexpr Choice<SampleFormat> kFormats[] = {
        {"auto", SampleFormat::Auto}, {"rocklab", SampleFormat::Rocklab},
        {"csv", SampleFormat::Csv},   {"lammps", SampleFormat::Lammps},
        {"yade", SampleFormat::Yade}, {"vtp", SampleFormat::Vtp}};
    static constexpr Choice<LengthUnit> kUnits[] = {{"m", LengthUnit::M},
                                                    {"cm", LengthUnit::Cm},
                                                    {"mm", LengthUnit::Mm},
                                                    {"um", LengthUnit::Um}};
    f(kind,
      {"sample.kind",
       units::text,
       {},
       "spheres: one disk or sphere per grain; grains: breakable superparticles, pebbles "
       "joined by intragranular bonds (grains.*, grain_bonds.*; Li & Holt section 2.2); "
       "clumps: the same shapes as rigid bodies (grains.*, clumps.*); file: the disks or "
       "spheres of sample.file, formed and cemented like a generated sample unless "
       "formation.enabled = false"},
      kKinds);
    f.section("sample.", packing);
    f(file, {"sample.file",
             units::path,
             {},
             "kind = file: the sample's particles (rocklab packing, CSV, LAMMPS data, Yade "
             "text, VTK .vtp), relative to the protocol file"});
    f(format,
      {"sample.format",
       units::text,
       {},
       "kind = file: the file's format; auto: by extension (.txt/.packing rocklab, .csv, "
       ".data/.lmp lammps, .yade, .vtp)"},
      kFormats);
    f(file_unit,
      {"sample.file_unit",
       units::text,
       {},
       "kind = file: the length unit of the file's numbers where the file does not "
       "name one (a CSV header may; the rocklab format is in metres)"},
      kUnits);
    f(aspect_axial, {"sample.aspect_axial", units::none, Range::closed(0.1, 10),
                     "axial length over lateral length of the generated box"});
    f.section("grains.", grain_shape);
    f(clump_break_stress,
      {"clumps.break_stress_MPa", units::MPa, Range::closed(0, 1e5),
       "a clump breaks into its pebbles when F / d^2 of its largest pebble contact force F "
       "reaches this (d: its equivalent diameter; McDowell & Bolton 1998); 0: unbreakable"});
  }
};

// The grains' material: the fields every contact law reads and each law's own (the law
// registry's rows), and the walls' friction.
struct MaterialSettings {
  Material grain;
  double wall_friction = 0.0;

  template <class F>
  void fields(F& f) {
    f.section("", grain);
    for (const ContactLawEntry* law : contactLaws()) {
      for (const MaterialKey& k : law->keys) f(grain.*k.member, k.field);
    }
    f(wall_friction, {"wall_friction", units::none, Range::closed(0, 10), "grain-wall friction"});
  }
};

// The cement installed after formation (`bonds.*`): its kind and which pairs it joins.
struct CementSettings {
  bool enabled = true;
  BondKind kind;
  double gap_ratio = 0.01;  // -, of the smaller radius

  template <class F>
  void fields(F& f) {
    f(enabled, {"enabled", units::text, {}, "cement the sample after formation (parallel bonds)"});
    f.section("", kind);
    f(gap_ratio, {"gap_ratio", units::none, Range::closed(0, 1),
                  "pairs closer than this times the smaller radius are cemented too"});
  }
};

// Formation under stress (Li & Holt section 1): densified at the lateral stress with a low
// friction, then brought to the formation state with the grains' own.
struct FormationSettings {
  bool enabled = true;
  double axial_stress = 30.0 * kMPa;
  double lateral_stress = 15.0 * kMPa;
  double friction = 0.0;
  double stress_tolerance = 0.01;
  double unbalanced_force_ratio = 0.01;
  std::int64_t max_steps = 2000000;
  double local_damping = 0.7;
  double density_scaling = 1.0;
  double densified_porosity_change = 0.0;
  std::int64_t densified_window_steps = 20000;
  bool reuse = false;

  template <class F>
  void fields(F& f) {
    f(enabled, {"enabled",
                units::text,
                {},
                "form the sample under stress (densify, then take the formation state); false: "
                "use it as it is (a sample from a file), its walls at its box"});
    f(axial_stress,
      {"axial_stress_MPa", units::MPa, Range::leftOpen(0, 1e4), "axial stress of formation"});
    f(lateral_stress,
      {"lateral_stress_MPa", units::MPa, Range::leftOpen(0, 1e4), "lateral stress of formation"});
    f(friction, {"friction", units::none, Range::closed(0, 10),
                 "grain friction while the sample is densified (isotropically, at the lateral "
                 "formation stress); low friction packs densely"});
    f(stress_tolerance, {"stress_tolerance", units::none, Range::closed(1e-6, 0.5),
                         "settled when every wall is within this fraction of its target"});
    f(unbalanced_force_ratio,
      {"unbalanced_force_ratio", units::none, Range::closed(1e-7, 1),
       "and the mean unbalanced force is below this fraction of the mean contact force"});
    f(max_steps, {"max_steps", units::none, Range::closed(100, 1e10),
                  "give up settling after this many steps"});
    f(local_damping, {"local_damping", units::none, Range::rightOpen(0, 1),
                      "local damping while the sample is densified (numerics.local_damping "
                      "is the rest's); less lets the frictionless grains rearrange sooner"});
    f(density_scaling,
      {"density_scaling", units::none, Range::closed(1, 16),
       "density scaling while the sample is formed (numerics.density_scaling is the loading's): "
       "the formed sample depends on the path to it, so 1 forms it at its physical masses"});
    f(densified_porosity_change,
      {"densified_porosity_change", units::none, Range::closed(0, 0.1),
       "densification also ends, with the walls at their stress, when the porosity fell by "
       "less than this over formation.densified_window_steps (0: only the unbalanced force "
       "ratio ends it)"});
    f(densified_window_steps, {"densified_window_steps", units::none, Range::closed(100, 1e9),
                               "the window of formation.densified_porosity_change"});
    f(reuse, {"reuse",
              units::text,
              {},
              "keep the formed sample beside the lab and start from it in every later run whose "
              "formation is the same (rigs/common/formed_samples.hpp): the same results, bit for "
              "bit, without the formation's steps"});
  }
};

// The frame's servo (rigs/common/frame.hpp).
struct ServoSettings {
  double alpha = 0.5;
  double speed_radii_per_step = 1e-3;

  template <class F>
  void fields(F& f) {
    f(alpha, {"servo_alpha", units::none, Range::leftOpen(0, 1),
              "servo: fraction of the stress error closed per step"});
    f(speed_radii_per_step, {"servo_speed_radii_per_step", units::none, Range::leftOpen(0, 1),
                             "servo: largest wall move per step, in mean radii"});
  }
};

// Quasi-static control is measured, not assumed (measurements.hpp).
struct QuasiStaticLimits {
  double unbalanced = 0.02;  // -, mean unbalanced force ratio of a loading stage
  double inertial = 1e-3;    // -, largest inertial number

  template <class F>
  void fields(F& f) {
    f(unbalanced, {"quasi_static_unbalanced", units::none, Range::leftOpen(0, 10),
                   "warn when the mean unbalanced force ratio of a loading stage exceeds this"});
    f(inertial, {"quasi_static_inertial", units::none, Range::leftOpen(0, 10),
                 "warn when the inertial number of a loading stage exceeds this"});
  }
};

struct OutputSettings {
  std::int64_t record_every_steps = 500;
  bool snapshots = true;
  std::int64_t snapshot_every_steps = 0;  // 0: only at the ends of stages
  double checkpoint_every_s = 60.0;       // wall time between checkpoints inside a stage

  template <class F>
  void fields(F& f) {
    f(record_every_steps, {"record_every_steps", units::none, Range::closed(1, 1e9),
                           "steps between recorded measurements"});
    f(snapshots, {"snapshots",
                  units::text,
                  {},
                  "save frames of the state (particles, contacts, bonds, walls) when the sample is "
                  "formed and at the end of each loading stage, for reports and ParaView"});
    f(snapshot_every_steps, {"snapshot_every_steps", units::none, Range::closed(0, 1e12),
                             "also save a frame every this many loading steps (0: none)"});
    f(checkpoint_every_s,
      {"checkpoint_every_s", units::s, Range::closed(0.01, 1e7),
       "wall time between checkpoints inside a stage (one is written at every stage's end "
       "too): how much of a killed run `rocklab resume` must do again"});
  }
};

// Every shared section: what a specimen is built, formed and recorded from.
struct SpecimenSettings {
  ProtocolInfo protocol;
  SampleSettings sample;
  MaterialSettings material;
  CementSettings cement;
  BondKind grain_bonds = BondKind::grains();
  FormationSettings formation;
  SimulationConfig simulation;  // material.contact_law and the core's numerics.*
  ServoSettings servo;
  QuasiStaticLimits quasi_static;
  OutputSettings output;

  // Rules across sections: a sample to build (a count, or a file that reads as a packing of
  // the protocol's dimension).
  void validate() const;

  template <class F>
  void fields(F& f) {
    f.section("protocol.", protocol);
    f.section("", sample);
    f.section("material.", material);
    f.section("bonds.", cement);
    f.section("grain_bonds.", grain_bonds);
    f.section("formation.", formation);
    f.section("", simulation);
    f.section("numerics.", servo);
    f.section("numerics.", quasi_static);
    f.section("output.", output);
  }
};

}  // namespace rocklab::rigs
