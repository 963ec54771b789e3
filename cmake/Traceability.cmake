# Traceability (REQ-HARNESS-001): every requirement in spec/ is cited by a test and every
# cited ID exists. ci/trace.py reads spec/*.md and the REQ tags of every registered
# Catch2 binary (plus `cites:` lines of script tests), fails on a gap and writes
# <build>/traceability.md.
get_property(_miner_test_targets GLOBAL PROPERTY MINER_TEST_TARGETS)
set(_miner_test_files "")
foreach(_t ${_miner_test_targets})
  list(APPEND _miner_test_files "$<TARGET_FILE:${_t}>")
endforeach()
add_test(NAME traceability
  COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/ci/trace.py ${_miner_test_files}
          --spec ${PROJECT_SOURCE_DIR}/spec
          --out ${PROJECT_BINARY_DIR}/traceability.md
          --extra-citations ${PROJECT_SOURCE_DIR}/ci/test_trace.py ${PROJECT_SOURCE_DIR}/ci/check_readme.py ${PROJECT_SOURCE_DIR}/ci/fuzz.sh
                            ${PROJECT_SOURCE_DIR}/ci/check_report.py ${PROJECT_SOURCE_DIR}/ci/cluster_test.sh
                            ${PROJECT_SOURCE_DIR}/ci/install_test.sh ${PROJECT_SOURCE_DIR}/src/python/tests/test_miner.py
                            ${PROJECT_SOURCE_DIR}/ci/check_layout.py)
add_test(NAME traceability-checker-selftest
  COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/ci/test_trace.py)
add_test(NAME layout COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/ci/check_layout.py ${PROJECT_SOURCE_DIR})
add_test(NAME readme-quickstart
  COMMAND ${Python3_EXECUTABLE} ${PROJECT_SOURCE_DIR}/ci/check_readme.py ${PROJECT_SOURCE_DIR})
set_tests_properties(traceability traceability-checker-selftest readme-quickstart layout PROPERTIES LABELS unit)
