# The API reference: target `docs` renders the Doxygen comments of include/
# (maths written \f$ ... \f$ and \f[ ... \f] through MathJax, so no LaTeX is
# needed) into ${PROJECT_BINARY_DIR}/docs/html/index.html. Defined only when
# posefuse is the top-level project and Doxygen is found; never part of ALL.
# Doxygen's warnings are errors (WARN_AS_ERROR), so the target fails on an
# undocumented parameter or a broken reference.
if(NOT PROJECT_IS_TOP_LEVEL)
  return()
endif()
find_package(Doxygen QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "posefuse: target docs (API reference) not defined: Doxygen not found (Debian: doxygen)")
  return()
endif()
set(POSEFUSE_DOCS_OUTPUT "${PROJECT_BINARY_DIR}/docs")
configure_file("${PROJECT_SOURCE_DIR}/docs/Doxyfile.in" "${POSEFUSE_DOCS_OUTPUT}/Doxyfile" @ONLY)
add_custom_target(docs
  COMMAND "${DOXYGEN_EXECUTABLE}" "${POSEFUSE_DOCS_OUTPUT}/Doxyfile"
  WORKING_DIRECTORY "${PROJECT_SOURCE_DIR}"
  COMMENT "API reference: ${POSEFUSE_DOCS_OUTPUT}/html/index.html"
  VERBATIM)
