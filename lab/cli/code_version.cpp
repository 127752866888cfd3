#include <string>

#include "lab/cli/build_info.hpp"
#include "lab/notebook/notebook.hpp"

namespace rocklab {

std::string codeVersion() {
  static const std::string version = [] {
    const std::string revision = kGitRevision;
    if (revision != "unknown" && !revision.ends_with("-dirty")) return revision;
    return revision + " build " + notebook::fileSha256("/proc/self/exe").substr(0, 12);
  }();
  return version;
}

}  // namespace rocklab
