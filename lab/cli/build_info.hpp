#pragma once
// What was built: version, git revision, build type and flags (generated at build time).

#include <string>

namespace rocklab {
extern const char* const kVersion;
extern const char* const kGitRevision;
extern const char* const kBuildType;
extern const char* const kBuildFlags;

// What names the code that makes a run (runs.code_version, a checkpoint's "code"): the git
// revision of a clean tree. A dirty tree's revision (or "unknown", a build outside git) names
// other code as well, so its build is also named by the first 12 hex digits of its bytes'
// sha256: a run resumes, or a reference keeps a run, only under the very build that made it.
std::string codeVersion();
}  // namespace rocklab
