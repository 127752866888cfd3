# Writes build_info.cpp with the git revision at build time (not configure time), and only
# touches it when the text changes, so an unchanged tree does not relink.
execute_process(
  COMMAND git rev-parse --short=12 HEAD
  WORKING_DIRECTORY ${SRC}
  OUTPUT_VARIABLE rev OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT rev)
  set(rev "unknown")
else()
  execute_process(
    COMMAND git status --porcelain --untracked-files=no
    WORKING_DIRECTORY ${SRC}
    OUTPUT_VARIABLE dirty OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(dirty)
    string(APPEND rev "-dirty")
  endif()
endif()
file(WRITE ${OUT}.tmp
"#include \"lab/cli/build_info.hpp\"
namespace rocklab {
const char* const kVersion = \"${VERSION}\";
const char* const kGitRevision = \"${rev}\";
const char* const kBuildType = \"${BUILD_TYPE}\";
const char* const kBuildFlags = \"${FLAGS}\";
}  // namespace rocklab
")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUT}.tmp)
