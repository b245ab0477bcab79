# Writes version.hpp from version.hpp.in with `git describe` of the source tree
# (run at build time by common/CMakeLists.txt). configure_file leaves the file,
# and so its timestamp, alone when nothing changed: no rebuild for nothing.
execute_process(
  COMMAND git describe --always --dirty --tags
  WORKING_DIRECTORY ${SOURCE_DIR}
  OUTPUT_VARIABLE OUTBURST_GIT_VERSION
  OUTPUT_STRIP_TRAILING_WHITESPACE
  ERROR_QUIET)
if(NOT OUTBURST_GIT_VERSION)
  set(OUTBURST_GIT_VERSION "unknown")
endif()
configure_file(${INPUT} ${OUTPUT} @ONLY)
