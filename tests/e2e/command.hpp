#pragma once
// Runs the rocklab command for the end-to-end tests.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace rocklab::testing {

// Runs `rocklab ARGS`, stderr folded into `out`; returns the exit status.
inline int runRocklab(const std::string& args, std::string* out = nullptr) {
  const std::string cmd = std::string(ROCKLAB_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string text;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), pipe)) text += buf.data();
  const int status = pclose(pipe);
  if (out) *out = text;
  return WEXITSTATUS(status);
}

}  // namespace rocklab::testing
