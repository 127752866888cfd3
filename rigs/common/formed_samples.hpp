#pragma once
// Formed samples shared between the runs of a lab (formation.reuse = true).
//
// Forming a sample under stress is most of a quasi-static test's steps (the 2D superparticle
// UCS test at 1,500 grains: 615,500 of 690,000), and nothing that comes after it enters it:
// not the loading, not the cement (installed on the formed sample), and not the grains'
// strengths for as long as no intragranular bond breaks. So a run with reuse on keeps its
// formed sample in the folder beside the lab, under the hash of what its formation depends on
// (formationIdentity); a later run with the same hash starts from it. It draws its grains'
// strengths again from the stream and in the order its own build would have (the bonds are
// the same: they are installed on the packing, before the formation), and takes the formed
// sample only if each of those bonds is stronger than the highest stresses it carried while
// the sample formed: its own formation would then have gone the same way, step for step. The
// run is therefore the one it would have been, bit for bit (tests/e2e/test_formed_samples.cpp
// compares the final state hashes), and records the formation's series and messages as the
// run that formed the sample recorded them.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs {

// The folder of the formed samples of the lab notebook at `lab`.
std::string formedSamplesDir(const std::string& lab);

// What a protocol's formation depends on, one "key = value" a line (keys at their default
// left out, as Settings::identity()): the rig and the keys of the shared sections (only they
// reach buildSpecimen and formAndCement), less those used only after the formation (the
// cement's bonds.*, numerics.density_scaling, which the formation's own replaces), the
// grains' strengths (held to the formation's peak stresses instead), the protocol's name,
// description and key results, and formation.reuse itself.
std::string formationIdentity(const protocol::Settings& settings);

// A recorder that passes everything on and keeps the series and messages of the formation.
// Anything else recorded meanwhile (an event, a result) is not kept: the capture is then
// incomplete and the sample is not kept for reuse.
class FormationCapture : public Recorder {
 public:
  explicit FormationCapture(Recorder& inner) : inner_(inner) {}
  void series(std::string_view name, std::uint64_t step, double time, double value) override;
  void event(const EventRecord& e) override;
  void result(std::string_view name, double value, std::string_view unit) override;
  void message(std::uint64_t step, double time, std::string_view level,
               std::string_view text) override;
  void stageTiming(std::string_view stage, double seconds, std::uint64_t calls) override;
  void snapshot(std::string_view stage, std::string_view label, const Frame& frame) override;
  void wave(const WaveRecord& w) override;
  bool complete() const { return complete_; }
  const FormationRecords& records() const { return records_; }

 private:
  Recorder& inner_;
  FormationRecords records_;
  bool complete_ = true;
};

// Keeps a sample at the end of its formation for later runs: `sp` with its grain bonds' peak
// stresses (the simulation tracked them from the formation's start), the steps of the
// densification and of the formation, and the records captured. Written whole or not at all
// (a temporary file renamed). Returns why it was not kept, empty when it was.
template <int D>
std::string keepFormed(const FormedSamples& store, const Specimen<D>& sp,
                       std::uint64_t densification_steps, std::uint64_t formation_steps,
                       const FormationCapture& capture);

// The lab's formed sample for these settings, with the run's own grain strengths drawn again,
// or nothing: `why` then says why not (no sample formed yet, a bond weaker than the stress it
// carried while the sample formed, ...).
template <int D>
std::optional<Specimen<D>> reuseFormed(const FormedSamples& store, const SpecimenSettings& s,
                                       std::string& why);

}  // namespace rocklab::rigs
