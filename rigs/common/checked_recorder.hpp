#pragma once
// A recorder that holds a rig to its declared outputs (outputs.hpp): every series, result
// and event it records must be declared, or the run stops with the name (a programming
// error the end-to-end tests catch, not a protocol's). Everything else passes through.

#include <stdexcept>
#include <string>
#include <unordered_set>

#include "rigs/common/experiment.hpp"
#include "rigs/common/outputs.hpp"

namespace rocklab::rigs {

class CheckedRecorder : public Recorder {
 public:
  CheckedRecorder(Recorder& inner, const Outputs& outputs, std::string rig)
      : inner_(inner), outputs_(outputs), rig_(std::move(rig)) {}

  void series(std::string_view name, std::uint64_t step, double time, double value) override {
    check(OutputKind::Series, name, "series");
    inner_.series(name, step, time, value);
  }
  void event(const EventRecord& e) override {
    check(OutputKind::Event, e.kind, "event");
    inner_.event(e);
  }
  void result(std::string_view name, double value, std::string_view unit) override {
    check(OutputKind::Result, name, "result");
    inner_.result(name, value, unit);
  }
  void message(std::uint64_t step, double time, std::string_view level,
               std::string_view text) override {
    inner_.message(step, time, level, text);
  }
  void stageTiming(std::string_view stage, double seconds, std::uint64_t calls) override {
    inner_.stageTiming(stage, seconds, calls);
  }
  void snapshot(std::string_view stage, std::string_view label, const Frame& frame) override {
    inner_.snapshot(stage, label, frame);
  }
  void wave(const WaveRecord& w) override { inner_.wave(w); }

 private:
  void check(OutputKind kind, std::string_view name, const char* what) {
    std::string key = std::to_string(static_cast<int>(kind)) + std::string(name);
    if (seen_.count(key)) return;
    if (!outputs_.declares(kind, name)) {
      throw std::logic_error("the " + rig_ + " rig recorded the " + what + " '" +
                             std::string(name) + "', which its outputs do not declare (" + "rigs/" +
                             rig_ + "/outputs.cpp)");
    }
    seen_.insert(std::move(key));
  }
  Recorder& inner_;
  const Outputs& outputs_;
  std::string rig_;
  std::unordered_set<std::string> seen_;
};

}  // namespace rocklab::rigs
