# Writes the version header at build time (not only at configure time), so that a binary built
# after a new commit names that commit. configure_file rewrites the header only when the text
# changes: an unchanged version recompiles nothing.
# In: SRC (version.hpp.in), DST (the header), SOURCE_DIR (the checkout), PROJECT_VERSION.
execute_process(COMMAND git describe --always --dirty WORKING_DIRECTORY ${SOURCE_DIR}
  OUTPUT_VARIABLE _git OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE _git_rc)
if(_git_rc EQUAL 0 AND _git)
  set(NCFSIM_GIT_SUFFIX "+${_git}")
else()
  set(NCFSIM_GIT_SUFFIX "")
endif()
configure_file(${SRC} ${DST} @ONLY)
