#pragma once
// What was built: version, git revision, build type and flags (generated at build time).

namespace rocklab {
extern const char* const kVersion;
extern const char* const kGitRevision;
extern const char* const kBuildType;
extern const char* const kBuildFlags;
}  // namespace rocklab
