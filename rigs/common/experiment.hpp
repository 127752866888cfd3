#pragma once
// What every rig needs around the simulation: a recorder for its measurements (the lab
// notebook in `rocklab run`, memory in tests), progress and interruption.

#include <chrono>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "lab/core/frame.hpp"
#include "lab/notebook/records.hpp"
#include "rigs/common/journal.hpp"

namespace rocklab::rigs {

using notebook::EventRecord;
using notebook::WaveRecord;

class Recorder {
 public:
  virtual ~Recorder() = default;
  virtual void series(std::string_view name, std::uint64_t step, double time, double value) = 0;
  virtual void event(const EventRecord& e) = 0;
  virtual void result(std::string_view name, double value, std::string_view unit) = 0;
  virtual void message(std::uint64_t step, double time, std::string_view level,
                       std::string_view text) = 0;
  virtual void stageTiming(std::string_view stage, double seconds, std::uint64_t calls) = 0;
  // A frame of the state for reports and ParaView (`label` says which moment it is).
  virtual void snapshot(std::string_view stage, std::string_view label, const Frame& frame) = 0;
  virtual void wave(const WaveRecord& w) = 0;
};

// Raised when the user interrupts a run (Ctrl-C, SIGTERM); the run is closed as
// `interrupted` with what it recorded until then.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where a lab keeps its formed samples (formed_samples.hpp), and the name of this run's.
struct FormedSamples {
  std::string dir;  // beside the lab: formedSamplesDir()
  std::string key;  // the hash of formationIdentity(), its files and the build
  std::string file() const { return dir + "/" + key + ".formed"; }
};

// Progress on stderr (when it is a terminal and not quiet) and the interruption check.
class RunControl {
 public:
  RunControl(bool show_progress, std::function<const char*()> interrupted)
      : show_(show_progress), interrupted_(std::move(interrupted)) {}
  // Throws Interrupted when a stop was requested; prints progress at most 4 times a second.
  // `fraction` < 0 when the stage's length is not known in advance.
  void tick(std::string_view stage, std::uint64_t steps, double fraction, std::string_view detail);
  void done();  // ends the progress line
  // The run's checkpoints (none: units always run, nothing is written).
  void setJournal(Journal* j) { journal_ = j; }
  Journal::Unit unit(std::string_view name) {
    return journal_ ? journal_->begin(name) : Journal::Unit{};
  }
  // True while a resumed run replays what it had done: nothing is recorded.
  bool replaying() const { return journal_ && journal_->replaying(); }
  // The lab's formed samples and this run's formation's name in them (formation.reuse;
  // formed_samples.hpp); null: the run forms its sample and keeps nothing.
  void setFormedSamples(FormedSamples f) { formed_ = std::move(f); }
  const FormedSamples* formedSamples() const { return formed_.dir.empty() ? nullptr : &formed_; }

 private:
  bool show_;
  std::function<const char*()> interrupted_;
  std::chrono::steady_clock::time_point last_print_{};
  std::chrono::steady_clock::time_point stage_start_{};
  std::string stage_;
  std::uint64_t stage_steps0_ = 0;
  bool printed_ = false;
  Journal* journal_ = nullptr;
  FormedSamples formed_;
};

}  // namespace rocklab::rigs
