# Warnings for posefuse's own targets only (never exported to consumers).
option(POSEFUSE_WERROR "Treat warnings as errors in posefuse's own targets" OFF)
add_library(posefuse_warnings INTERFACE)
target_compile_options(posefuse_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion>)
if(POSEFUSE_WERROR)
  target_compile_options(posefuse_warnings INTERFACE -Werror)
endif()
