#include "rigs/common/journal.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace rocklab::rigs {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'R', 'K', 'J', 'O', 'U', 'R', '0', '1'};

void writeAtomically(const fs::path& path, const std::string& bytes) {
  const fs::path tmp = path.string() + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw std::runtime_error("cannot write checkpoint '" + tmp.string() + "'");
  }
  fs::rename(tmp, path);  // a kill never leaves half a checkpoint
}

std::string readAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("no checkpoint '" + path.string() + "'");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

Journal::Journal(Options o) : o_(std::move(o)) {}

Journal Journal::resuming(Options o) {
  const fs::path manifest = fs::path(o.dir) / "journal";
  if (!fs::exists(manifest)) {
    throw std::runtime_error("no checkpoint to resume from in " + o.dir +
                             " (the run stopped before its first checkpoint: run it again)");
  }
  std::map<std::string, std::string> m;
  std::istringstream in(readAll(manifest));
  for (std::string line; std::getline(in, line);) {
    const auto sp = line.find(' ');
    if (sp != std::string::npos) m[line.substr(0, sp)] = line.substr(sp + 1);
  }
  if (m["protocol"] != o.protocol_hash) {
    throw std::runtime_error("the protocol changed since the checkpoint (its hash was " +
                             m["protocol"] + ", it is " + o.protocol_hash +
                             "): a resumed run must be the same run; start a new one");
  }
  if (m["code"] != o.code_version) {
    throw std::runtime_error("the checkpoint was written by rocklab " + m["code"] + ", this is " +
                             o.code_version +
                             ": only the same code continues a run bit for bit; resume with that "
                             "rocklab or start a new run");
  }
  Journal j(std::move(o));
  j.replaying_ = true;
  j.resume_unit_ = std::stoi(m["unit"]);
  j.resume_phase_ = m["phase"] == "mid" ? Phase::Mid : Phase::End;
  j.resume_seq_ = std::stoull(m["seq"].empty() ? "0" : m["seq"]);
  if (j.resume_phase_ == Phase::Mid)
    j.last_mid_ = j.file(j.resume_unit_, Phase::Mid, j.resume_seq_);
  j.resume_mark_ = m["mark"];
  j.resume_point_ = "unit " + m["unit"] + " (" + m["name"] + "), " + m["phase"];
  return j;
}

Journal::Unit Journal::begin(std::string_view name) {
  return Unit(this, ordinal_++, std::string(name));
}

std::string Journal::file(int ordinal, Phase phase, std::uint64_t seq) const {
  const std::string name = "unit-" + std::to_string(ordinal) +
                           (phase == Phase::End ? ".end" : ".mid-" + std::to_string(seq));
  return (fs::path(o_.dir) / name).string();
}

void Journal::write(int ordinal, Phase phase, std::string_view name, const std::string& bytes) {
  const auto start = std::chrono::steady_clock::now();
  // The notebook first: the mark says what the checkpoint's state has recorded.
  const std::string mark = o_.mark ? o_.mark() : std::string();
  fs::create_directories(o_.dir);
  std::string data(kMagic, sizeof kMagic);
  const auto n = static_cast<std::uint64_t>(name.size());
  data.append(reinterpret_cast<const char*>(&n), sizeof n);
  data.append(name);
  data += bytes;
  // The checkpoint first, under a name of its own; the manifest's rename then makes it the
  // one to resume from, with the notebook mark taken with it. A kill between the two leaves
  // the manifest naming the previous checkpoint, which is still there.
  const std::uint64_t seq = resume_seq_ + writes_ + 1;
  const std::string path = file(ordinal, phase, seq);
  writeAtomically(path, data);
  std::ostringstream manifest;
  manifest << "unit " << ordinal << "\nphase " << (phase == Phase::End ? "end" : "mid") << "\nseq "
           << seq << "\nname " << name << "\nprotocol " << o_.protocol_hash << "\ncode "
           << o_.code_version << "\nmark " << mark << "\n";
  writeAtomically(fs::path(o_.dir) / "journal", manifest.str());
  if (!last_mid_.empty()) fs::remove(last_mid_);
  last_mid_ = phase == Phase::Mid ? path : std::string();
  write_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++writes_;
}

std::string Journal::read(int ordinal, Phase phase, std::string_view name) const {
  const std::string path = file(ordinal, phase, phase == Phase::Mid ? resume_seq_ : 0);
  const std::string data = readAll(path);
  std::uint64_t n = 0;
  if (data.size() < sizeof kMagic + sizeof n ||
      data.compare(0, sizeof kMagic, kMagic, sizeof kMagic) != 0) {
    throw std::runtime_error("'" + path + "' is not a rocklab run checkpoint");
  }
  std::memcpy(&n, data.data() + sizeof kMagic, sizeof n);
  const std::string stored = data.substr(sizeof kMagic + sizeof n, n);
  if (stored != name) {
    throw std::runtime_error("the run's units differ from the checkpoint's: unit " +
                             std::to_string(ordinal) + " is '" + std::string(name) + "' now, '" +
                             stored + "' in the checkpoint");
  }
  return data.substr(sizeof kMagic + sizeof n + n);
}

void Journal::clear() {
  fs::remove_all(o_.dir);
}

}  // namespace rocklab::rigs
