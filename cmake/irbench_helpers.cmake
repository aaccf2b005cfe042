# irbench_test(NAME SOURCES... LIBS ... [LABELS label] [COST seconds]
#              [SHARED_RENDERS] [SLOW_UNDER_SANITIZERS filter]): a GoogleTest
# binary registered with CTest. Its tests carry the CTest label "closed_loop"
# when it is declared under tests/ (renders, the CLI, the tracker end to end)
# and "unit" beside a library; `ctest -L unit` runs the latter
# (ci/sanitize.sh). LABELS replaces that label (one label:
# gtest_discover_tests splits lists). COST: about how long its longest test
# runs; `ctest -j` starts the costliest first, so a fresh build directory (no
# CTestCostData.txt yet) does not end on a long test alone.
# SHARED_RENDERS: its tests use tests/shared_render.h, whose renders CTest
# clears before the first and after the last of them (fixture test_renders).
# In the sanitizer build (IRBENCH_SANITIZE) a unit-test binary is one CTest
# test that runs all its tests in one process.
# SLOW_UNDER_SANITIZERS: a --gtest_filter of the unit tests that take minutes
# under ASan ("*": all of them); the sanitizer build (IRBENCH_SANITIZE) leaves
# them out, and a build with IRBENCH_UNIT_TESTS=OFF builds and runs only them:
# CI's two builds (ci/test.sh) run every unit test once between them.
function(irbench_test name)
  cmake_parse_arguments(ARG "SHARED_RENDERS" "COST;SLOW_UNDER_SANITIZERS" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT ARG_LABELS)
    file(RELATIVE_PATH rel_dir "${PROJECT_SOURCE_DIR}" "${CMAKE_CURRENT_SOURCE_DIR}")
    if(rel_dir STREQUAL "tests" OR rel_dir MATCHES "^tests/")
      set(ARG_LABELS closed_loop)
    else()
      set(ARG_LABELS unit)
    endif()
  endif()
  set(filter "")
  if(ARG_LABELS STREQUAL "unit" AND IRBENCH_SANITIZE)
    if(ARG_SLOW_UNDER_SANITIZERS STREQUAL "*")
      return()
    elseif(ARG_SLOW_UNDER_SANITIZERS)
      set(filter "-${ARG_SLOW_UNDER_SANITIZERS}")
    endif()
  elseif(ARG_LABELS STREQUAL "unit" AND NOT IRBENCH_UNIT_TESTS)
    if(NOT ARG_SLOW_UNDER_SANITIZERS)
      return()
    endif()
    set(filter "${ARG_SLOW_UNDER_SANITIZERS}")
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main GTest::gmock)
  target_compile_definitions(${name} PRIVATE
    IRBENCH_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    IRBENCH_BINARY_DIR="${PROJECT_BINARY_DIR}")
  # Every test's derived-data cache (the bounce light's volumes: common/paths.h
  # UserCacheDir) in the build folder, not the user's.
  set(properties LABELS "${ARG_LABELS}" ENVIRONMENT "IRBENCH_CACHE_DIR=${PROJECT_BINARY_DIR}/test-cache")
  if(ARG_COST)
    list(APPEND properties COST ${ARG_COST})
  endif()
  if(ARG_SHARED_RENDERS)
    list(APPEND properties FIXTURES_REQUIRED test_renders)
    get_property(declared GLOBAL PROPERTY IRBENCH_TEST_RENDERS_FIXTURE)
    if(NOT declared)
      set_property(GLOBAL PROPERTY IRBENCH_TEST_RENDERS_FIXTURE ON)
      add_test(NAME TestRenders.ClearBefore COMMAND ${CMAKE_COMMAND} -E rm -rf ${PROJECT_BINARY_DIR}/test-renders)
      add_test(NAME TestRenders.ClearAfter COMMAND ${CMAKE_COMMAND} -E rm -rf ${PROJECT_BINARY_DIR}/test-renders)
      set_tests_properties(TestRenders.ClearBefore PROPERTIES FIXTURES_SETUP test_renders)
      set_tests_properties(TestRenders.ClearAfter PROPERTIES FIXTURES_CLEANUP test_renders)
    endif()
  endif()
  if(IRBENCH_SANITIZE AND ARG_LABELS STREQUAL "unit")
    # Under the sanitizers one CTest test per binary, its tests in one process
    # as GoogleTest runs them by default (a failure still names the test): a
    # sanitized process start costs about half a second, and one per test made
    # CI's 273 unit tests take 135-151 s on 2 cores instead of 80 s; nor is
    # each binary run at build time to list its tests.
    if(filter)
      add_test(NAME ${name} COMMAND ${name} --gtest_filter=${filter})
    else()
      add_test(NAME ${name} COMMAND ${name})
    endif()
    set_tests_properties(${name} PROPERTIES ${properties})
  elseif(filter)
    gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 TEST_FILTER "${filter}" PROPERTIES ${properties})
  else()
    gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES ${properties})
  endif()
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
