#include "lab/cli/child_process.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>

namespace rocklab::cli {

std::string selfExecutable() {
  return std::filesystem::read_symlink("/proc/self/exe").string();
}

pid_t spawnLogged(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
    }
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(args[0].c_str(), argv.data());
    _exit(127);
  }
  if (pid < 0) throw std::runtime_error("cannot start a child process (fork failed)");
  return pid;
}

}  // namespace rocklab::cli
