#pragma once
// A rocklab command in a child process of its own (campaign tasks, reference runs at once):
// each child opens its own notebook, so runs in parallel never share a database.

#include <sys/types.h>

#include <string>
#include <vector>

namespace rocklab::cli {

// This executable's path, for a child to run the same build.
std::string selfExecutable();
// Starts `args` (args[0] the executable) with stdout and stderr to `log`; returns its pid.
// Throws std::runtime_error when no process can be started.
pid_t spawnLogged(const std::vector<std::string>& args, const std::string& log);

}  // namespace rocklab::cli
