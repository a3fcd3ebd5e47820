# Writes OUT from IN with the source tree's current `git describe` (KUSHNER_GIT_HASH): included by
# CMakeLists.txt at configure time, and run at every build (target kushner_git_version), so that output files
# name the commit the binary was built from, not the one CMake was configured at. configure_file leaves OUT
# untouched when nothing changed: no rebuild then.
#   cmake -DSOURCE_DIR=... -DIN=... -DOUT=... -DPROJECT_VERSION=... -P git_version.cmake
execute_process(COMMAND git -C ${SOURCE_DIR} describe --always --dirty --abbrev=12
                OUTPUT_VARIABLE KUSHNER_GIT_HASH OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT KUSHNER_GIT_HASH)
  set(KUSHNER_GIT_HASH "unknown")
endif()
configure_file(${IN} ${OUT} @ONLY)
