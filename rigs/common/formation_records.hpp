#pragma once
// The records of a sample's formation (its series and messages), kept with a formed sample
// for the runs that start from it (formed_samples.hpp).

#include <cstdint>
#include <string>
#include <vector>

#include "rigs/common/experiment.hpp"

namespace rocklab::rigs {

// The formation's records, as the run that formed the sample made them.
struct FormationRecords {
  struct Series {
    std::string name;
    std::uint64_t step = 0;
    double time = 0.0, value = 0.0;
    template <class Archive>
    void visit(Archive& ar) {
      ar("name", name), ar("step", step), ar("time", time), ar("value", value);
    }
  };
  struct Message {
    std::uint64_t step = 0;
    double time = 0.0;
    std::string level, text;
    template <class Archive>
    void visit(Archive& ar) {
      ar("step", step), ar("time", time), ar("level", level), ar("text", text);
    }
  };
  std::vector<Series> series;
  std::vector<Message> messages;
  template <class Archive>
  void visit(Archive& ar) {
    ar("series", series), ar("messages", messages);
  }
  void replay(Recorder& rec) const;
};

// Where a specimen came from when an earlier run formed it (formation.reuse): the formed
// sample's file, the steps its densification and formation took, and their records.
struct FormedOrigin {
  std::string file;
  std::uint64_t densification_steps = 0, formation_steps = 0;
  FormationRecords records;
  template <class Archive>
  void visit(Archive& ar) {
    ar("file", file), ar("densification_steps", densification_steps);
    ar("formation_steps", formation_steps), ar("records", records);
  }
};

}  // namespace rocklab::rigs
