#pragma once
// Per-stage timing (house rule 4 in README.md: what each stage of a run costs is measured and
// logged): a scope's wall time added to its stage's clock.

#include <chrono>
#include <cstdint>
#include <string>

namespace rocklab {

struct StageTime {
  double seconds = 0.0;
  std::uint64_t calls = 0;
};

// A stage's clock as the simulation reports it.
struct StageTiming {
  std::string name;
  double seconds = 0.0;
  std::uint64_t calls = 0;
};

// Adds the wall time from construction to destruction to `time` (nothing when null), and
// counts a call unless told not to (a stage timed in two parts counts once).
class StageClock {
 public:
  explicit StageClock(StageTime* time, bool counts_call = true)
      : time_(time), counts_(counts_call), start_(std::chrono::steady_clock::now()) {}
  ~StageClock() {
    if (!time_) return;
    time_->seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (counts_) ++time_->calls;
  }
  StageClock(const StageClock&) = delete;
  StageClock& operator=(const StageClock&) = delete;

 private:
  StageTime* time_;
  bool counts_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace rocklab
