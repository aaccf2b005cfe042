# irbench_test(NAME SOURCES... LIBS ... [LABELS label]): a GoogleTest binary
# registered with CTest. Its tests carry the CTest label "closed_loop" when it
# is declared under tests/ (renders, the CLI, the tracker end to end) and "unit"
# beside a library; `ctest -L unit` runs the latter (ci/sanitize.sh). LABELS
# replaces that label (one label: gtest_discover_tests splits lists).
function(irbench_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT ARG_LABELS)
    file(RELATIVE_PATH rel_dir "${PROJECT_SOURCE_DIR}" "${CMAKE_CURRENT_SOURCE_DIR}")
    if(rel_dir STREQUAL "tests" OR rel_dir MATCHES "^tests/")
      set(ARG_LABELS closed_loop)
    else()
      set(ARG_LABELS unit)
    endif()
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main GTest::gmock)
  target_compile_definitions(${name} PRIVATE
    IRBENCH_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    IRBENCH_BINARY_DIR="${PROJECT_BINARY_DIR}")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "${ARG_LABELS}")
  # `cmake --build <dir> --target irbench_unit_tests` builds the "unit" ones only.
  if(ARG_LABELS STREQUAL "unit")
    if(NOT TARGET irbench_unit_tests)
      add_custom_target(irbench_unit_tests)
    endif()
    add_dependencies(irbench_unit_tests ${name})
  endif()
endfunction()

# irbench_benchmark(NAME SOURCES... LIBS ...): a Google Benchmark binary (not a test).
function(irbench_benchmark name)
  if(NOT IRBENCH_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} benchmark::benchmark benchmark::benchmark_main)
endfunction()
