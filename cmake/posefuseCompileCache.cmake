# ccache as the compiler launcher of posefuse's own build when it is installed
# (Debian: ccache) and no launcher was chosen: a rebuild after a branch switch
# or a clean build folder then costs seconds instead of minutes. Never
# required; -DPOSEFUSE_CCACHE=OFF turns it off (CI's cold-build figure is
# measured without it).
option(POSEFUSE_CCACHE "Use ccache as the compiler launcher when it is found" ON)
if(POSEFUSE_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(POSEFUSE_CCACHE_PROGRAM ccache)
  if(POSEFUSE_CCACHE_PROGRAM)
    set(CMAKE_CXX_COMPILER_LAUNCHER "${POSEFUSE_CCACHE_PROGRAM}")
    message(STATUS "posefuse: compiling through ${POSEFUSE_CCACHE_PROGRAM}")
  endif()
endif()
