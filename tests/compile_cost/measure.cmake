# Compile cost of the umbrella header relative to a bare Eigen include.
#
# Run by ctest as `cmake -DCXX=... -DINCLUDE_DIR=... -DEIGEN_DIR=... -DWORK=...
# -DTARGET_RATIO=3 -DCEILING_RATIO=3 -P measure.cmake`. It parses (-fsyntax-only, C++20, -O0) one
# translation unit that includes <posefuse/posefuse.hpp> and one that
# includes only <Eigen/Core> and <Eigen/Geometry>, alternately, REPEAT times
# each, and compares the medians of their wall-clock times. It prints both
# figures and the ratio, and fails when the ratio exceeds CEILING_RATIO (the
# issue's target, 3x; about 2.4x measured on a loaded 2-core machine when
# the target was reached). What keeps it low: heavy inline functions and
# classes are templates (a defaulted `class Lazy = void` parameter where
# there is nothing else to deduce), so that a file compiles them only when
# it calls them, and the headers' own concept checks live in
# tests/static/concepts.cpp instead of the headers.
cmake_minimum_required(VERSION 3.21)
if(NOT DEFINED REPEAT)
  set(REPEAT 5)
endif()
file(MAKE_DIRECTORY "${WORK}")
file(WRITE "${WORK}/bare.cpp" "#include <Eigen/Core>\n#include <Eigen/Geometry>\nint main() { return 0; }\n")
file(WRITE "${WORK}/umbrella.cpp" "#include <posefuse/posefuse.hpp>\nint main() { return 0; }\n")

function(parse_time source out_var)
  string(TIMESTAMP t0 "%s%f")
  execute_process(COMMAND "${CXX}" -std=c++20 -O0 -fsyntax-only "-I${INCLUDE_DIR}" "-I${EIGEN_DIR}"
                          "${source}"
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  string(TIMESTAMP t1 "%s%f")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "compile_cost: ${source} does not compile:\n${err}")
  endif()
  math(EXPR us "${t1} - ${t0}")
  set(${out_var} ${us} PARENT_SCOPE)
endfunction()

function(median out_var)
  set(values ${ARGN})
  list(SORT values COMPARE NATURAL)
  list(LENGTH values n)
  math(EXPR mid "${n} / 2")
  list(GET values ${mid} m)
  set(${out_var} ${m} PARENT_SCOPE)
endfunction()

set(bare_times "")
set(umbrella_times "")
foreach(i RANGE 1 ${REPEAT})
  parse_time("${WORK}/bare.cpp" b)
  parse_time("${WORK}/umbrella.cpp" u)
  list(APPEND bare_times ${b})
  list(APPEND umbrella_times ${u})
endforeach()
median(bare_median ${bare_times})
median(umbrella_median ${umbrella_times})
# Ratio with two decimals, in integer arithmetic.
math(EXPR ratio_x100 "(${umbrella_median} * 100) / ${bare_median}")
math(EXPR target_x100 "${TARGET_RATIO} * 100")
math(EXPR ceiling_x100 "${CEILING_RATIO} * 100")
math(EXPR whole "${ratio_x100} / 100")
math(EXPR frac "${ratio_x100} % 100")
if(frac LESS 10)
  set(frac "0${frac}")
endif()
math(EXPR bare_ms "${bare_median} / 1000")
math(EXPR umbrella_ms "${umbrella_median} / 1000")
if(ratio_x100 GREATER target_x100)
  set(verdict "target ${TARGET_RATIO}x NOT met")
else()
  set(verdict "target ${TARGET_RATIO}x met")
endif()
message(STATUS "compile cost (median of ${REPEAT}, -fsyntax-only): bare Eigen ${bare_ms} ms, "
               "<posefuse/posefuse.hpp> ${umbrella_ms} ms, ratio ${whole}.${frac}: ${verdict}")
if(ratio_x100 GREATER ceiling_x100)
  message(FATAL_ERROR "compile_cost: the umbrella header costs ${whole}.${frac}x a bare Eigen include, "
                      "above the ceiling of ${CEILING_RATIO}x (target ${TARGET_RATIO}x)")
endif()
