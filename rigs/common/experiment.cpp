#include "rigs/common/experiment.hpp"

#include <cstdio>

namespace rocklab::rigs {

void RunControl::tick(std::string_view stage, std::uint64_t steps, double fraction,
                      std::string_view detail) {
  if (interrupted_) {
    if (const char* why = interrupted_()) throw Interrupted(why);
  }
  if (!show_) return;
  const auto now = std::chrono::steady_clock::now();
  if (stage != stage_) {
    stage_ = stage;
    stage_start_ = now;
    stage_steps0_ = steps;
  }
  if (now - last_print_ < std::chrono::milliseconds(250)) return;
  last_print_ = now;
  const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
  const double rate = elapsed > 0 ? static_cast<double>(steps - stage_steps0_) / elapsed : 0.0;
  char eta[32] = "";
  if (fraction > 0.0 && fraction < 1.0 && elapsed > 1.0) {
    const int left = static_cast<int>(elapsed * (1.0 - fraction) / fraction);
    std::snprintf(eta, sizeof eta, ", %d:%02d left", left / 60, left % 60);
  }
  char pct[16] = "";
  if (fraction >= 0.0) std::snprintf(pct, sizeof pct, " %3.0f%%", 100.0 * fraction);
  std::fprintf(stderr, "\r\033[K[%.*s]%s %.0f steps/s%s  %.*s", static_cast<int>(stage.size()),
               stage.data(), pct, rate, eta, static_cast<int>(detail.size()), detail.data());
  std::fflush(stderr);
  printed_ = true;
}

void RunControl::done() {
  if (printed_) std::fprintf(stderr, "\r\033[K");
  printed_ = false;
}

}  // namespace rocklab::rigs
