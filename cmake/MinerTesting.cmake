# Helpers that register MINER's Catch2 test binaries with CTest.
#
# miner_add_catch_test(<target> LABEL <label> SOURCES <src...> [LIBS <lib...>])
#   Builds one test binary, links the shared Catch2 runner (src/miner/testing),
#   registers every TEST_CASE as its own CTest test carrying <label>, and records
#   the binary for the traceability check (cmake/Traceability.cmake).
#
# Labels: unit, property, golden, statistical, bench-smoke, long, cluster, fuzz, mutation (CI skips long,
# cluster, fuzz and mutation: the test presets exclude the label regex `long|cluster|fuzz|mutation`).
function(miner_add_catch_test target)
  cmake_parse_arguments(ARG "" "LABEL" "SOURCES;LIBS" ${ARGN})
  if(NOT ARG_LABEL)
    message(FATAL_ERROR "miner_add_catch_test(${target}): LABEL is required")
  endif()
  add_executable(${target} ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE miner_test_main miner_flags ${ARG_LIBS})
  # --warn NoTests: a test whose filter matches no TEST_CASE fails instead of passing with
  # "No tests ran" (a ';' in a name cut CTest's filter short, and seven tests never ran).
  catch_discover_tests(${target} DISCOVERY_MODE PRE_TEST
    TEST_PREFIX "${target}: "
    EXTRA_ARGS --warn NoTests
    PROPERTIES LABELS "${ARG_LABEL}"
               ENVIRONMENT "MINER_SOURCE_DIR=${MINER_SOURCE_DIR}")
  set_property(GLOBAL APPEND PROPERTY MINER_TEST_TARGETS ${target})
endfunction()

# Unit tests live in a test/ folder beside the code they test (Drake style).
macro(miner_add_tests_from_subdirs)
  file(GLOB _miner_test_dirs LIST_DIRECTORIES true
       ${PROJECT_SOURCE_DIR}/src/miner/*/test ${PROJECT_SOURCE_DIR}/src/cli/test
       ${PROJECT_SOURCE_DIR}/src/bench/test)
  foreach(_dir ${_miner_test_dirs})
    if(EXISTS ${_dir}/CMakeLists.txt)
      add_subdirectory(${_dir})
    endif()
  endforeach()
endmacro()
