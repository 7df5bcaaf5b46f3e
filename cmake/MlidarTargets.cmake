# Helpers shared by every target: warnings on, include root at src/.
function(mlidar_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
endfunction()

# mlidar_library(NAME SOURCES... DEPS ...): one library per layer, named mlidar_NAME.
function(mlidar_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(mlidar_${name} ${ARG_SOURCES})
  add_library(mlidar::${name} ALIAS mlidar_${name})
  target_include_directories(mlidar_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(mlidar_${name} PUBLIC ${ARG_DEPS})
  mlidar_warnings(mlidar_${name})
endfunction()

# mlidar_test(NAME SOURCES... DEPS ...): one GoogleTest program registered with ctest.
# Tests find the shared real data and the mlidar executable through compiled-in
# defaults (MLIDAR_TEST_SHARED_DATA, MLIDAR_TEST_BIN); the environment variables
# MLIDAR_SHARED_DATA and MLIDAR_BIN override them.
function(mlidar_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  mlidar_warnings(${name})
  target_compile_definitions(${name} PRIVATE
    MLIDAR_TEST_SHARED_DATA="${MLIDAR_SHARED_DATA}" MLIDAR_TEST_BIN="$<TARGET_FILE:mlidar>")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60)
endfunction()

set(MLIDAR_SHARED_DATA "${PROJECT_SOURCE_DIR}/../shared/data" CACHE PATH "Folder of the shared real LiDAR data")
