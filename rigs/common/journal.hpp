#pragma once
// Checkpoints of a run and its resumption (`rocklab resume`). A rig's run is a sequence of
// units of work (the sample's making, a settling, a servo ramp, a loading): each unit that
// finishes writes a checkpoint of the objects it worked on and of its result, and a unit
// that runs long writes one of its loop's state every `output.checkpoint_every_s` of wall
// time. A resumed run executes the rig from its start again: the units already done are
// not run but read back from their checkpoints (the code between them runs again on the
// same state, so it does the same), the unit in progress continues from its last
// checkpoint, and what the run recorded after that checkpoint is removed from the notebook
// first; until then nothing is recorded twice (replaying()). Every run is deterministic, so
// the resumed run ends in the very state of an uninterrupted one.

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "lab/core/archive.hpp"

namespace rocklab::rigs {

class Journal {
 public:
  struct Options {
    std::string dir;        // the run's checkpoint folder
    double every_s = 60.0;  // wall time between checkpoints inside a unit
    std::string protocol_hash, code_version;
    // Flushes the notebook and returns how far the run's rows go: a resume removes what
    // lies beyond the mark of the checkpoint it continues from.
    std::function<std::string()> mark;
  };

  // A journal that writes checkpoints into o.dir (created at the first).
  explicit Journal(Options o);
  // The journal of a run to resume from the last checkpoint in o.dir; throws
  // std::runtime_error (with the reason) when there is none or the protocol or code
  // version differ from the checkpoint's.
  static Journal resuming(Options o);

  bool replaying() const { return replaying_; }
  // The notebook's mark (set once the notebook's run exists).
  void setMark(std::function<std::string()> mark) { o_.mark = std::move(mark); }
  // The notebook mark of the checkpoint a resume continues from.
  const std::string& resumeMark() const { return resume_mark_; }
  // Where the resume continues: "unit 5 (settle densification), mid" for messages.
  const std::string& resumePoint() const { return resume_point_; }
  // Removes the checkpoints (the run has completed).
  void clear();
  // The wall time spent writing checkpoints, and how many were written (the notebook keeps
  // them as the stage "checkpoints": their share of the run's time).
  double writeSeconds() const { return write_seconds_; }
  std::uint64_t writes() const { return writes_; }

  class Unit;
  Unit begin(std::string_view name);

 private:
  friend class Unit;
  enum class Phase { End, Mid };
  // A unit's end checkpoint; the mid checkpoints of a unit are numbered by the journal's
  // writes, so that a new one never replaces the one the manifest still names.
  std::string file(int ordinal, Phase phase, std::uint64_t seq = 0) const;
  void write(int ordinal, Phase phase, std::string_view name, const std::string& bytes);
  std::string read(int ordinal, Phase phase, std::string_view name) const;
  Options o_;
  int ordinal_ = 0;
  bool replaying_ = false;
  int resume_unit_ = -1;  // the unit the checkpoint is of
  Phase resume_phase_ = Phase::End;
  std::uint64_t resume_seq_ = 0;  // its number (a resumed run numbers its own on from it)
  std::string last_mid_;          // the mid checkpoint the manifest names, if any
  std::string resume_mark_, resume_point_;
  double write_seconds_ = 0.0;
  std::uint64_t writes_ = 0;
};

// One unit of a rig's run. Without a journal (a test, a rig run in memory) every call does
// nothing and the unit always runs.
//
//   Journal::Unit u = control.unit("settle");
//   if (u.done(result, sp)) return result;   // replaying: sp at the unit's end
//   u.resume(loop_state, sp);                 // replaying: sp and the loop at the checkpoint
//   while (...) { ...; u.tick(loop_state, sp); }
//   u.finish(result, sp);
//
// The objects and states are types with visit(Archive&) (or journal(Archive&) when reading
// back must rebuild them).
class Journal::Unit {
 public:
  Unit() = default;  // no journal
  Unit(Journal* j, int ordinal, std::string name)
      : j_(j), ordinal_(ordinal), name_(std::move(name)) {}

  template <class... T>
  bool done(T&... objects) {
    if (!j_ || !j_->replaying_ || !skipped()) return false;
    load(j_->read(ordinal_, Phase::End, name_), objects...);
    if (ordinal_ == j_->resume_unit_) j_->replaying_ = false;
    return true;
  }
  template <class... T>
  void resume(T&... objects) {
    if (!j_ || !j_->replaying_ || ordinal_ != j_->resume_unit_ || j_->resume_phase_ != Phase::Mid) {
      return;
    }
    load(j_->read(ordinal_, Phase::Mid, name_), objects...);
    j_->replaying_ = false;
  }
  // A checkpoint of the loop when the wall time since the last one has passed.
  template <class... T>
  void tick(T&... objects) {
    if (!j_ || ++calls_ % 64 != 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_).count() < j_->o_.every_s) return;
    j_->write(ordinal_, Phase::Mid, name_, save(objects...));
    last_ = std::chrono::steady_clock::now();
  }
  template <class... T>
  void finish(T&... objects) {
    if (j_) j_->write(ordinal_, Phase::End, name_, save(objects...));
  }

 private:
  bool skipped() const {
    return ordinal_ < j_->resume_unit_ ||
           (ordinal_ == j_->resume_unit_ && j_->resume_phase_ == Phase::End);
  }
  template <class Archive, class T>
  static void one(Archive& ar, T& x) {
    if constexpr (requires { x.journal(ar); }) {
      x.journal(ar);
    } else {
      ar("state", x);
    }
  }
  template <class... T>
  static std::string save(T&... objects) {
    ArchiveWriter w;
    (one(w, objects), ...);
    return w.bytes();
  }
  template <class... T>
  static void load(const std::string& bytes, T&... objects) {
    ArchiveReader r(bytes.data(), bytes.size());
    (one(r, objects), ...);
  }
  Journal* j_ = nullptr;
  int ordinal_ = 0;
  std::string name_;
  std::uint64_t calls_ = 0;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace rocklab::rigs
