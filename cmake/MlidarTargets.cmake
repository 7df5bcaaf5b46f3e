# Helpers shared by every target: warnings on, include root at src/.
function(mlidar_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
endfunction()

# Precompiled headers: the standard library, Eigen and (for tests) GoogleTest, which every file parses again
# otherwise (2.5 s of a test file's 8 s front end). Each is built once by a host target and reused by every target of
# its kind (same flags); only headers from outside the project, so editing ours never rebuilds them. Targets with
# flags of their own (LibTorch's, the Python module's) have none: a header of LibTorch's own took longer to build
# (47 s) than it saved its six files. MLIDAR_PRECOMPILE_HEADERS=OFF builds without.
option(MLIDAR_PRECOMPILE_HEADERS "Precompile the standard library, Eigen and GoogleTest headers" ON)
set(MLIDAR_PCH_HEADERS <algorithm> <array> <cmath> <cstdint> <filesystem> <functional> <map> <memory> <optional>
  <random> <span> <string> <vector> <Eigen/Dense>)

# mlidar_pch_host(NAME LIBRARY|PROGRAM HEADERS... DEPS...): a target that only builds a precompiled header of HEADERS
# (with the include folders of DEPS) for the targets that name it in mlidar_precompile.
function(mlidar_pch_host name kind)
  cmake_parse_arguments(ARG "" "" "HEADERS;DEPS" ${ARGN})
  if(NOT MLIDAR_PRECOMPILE_HEADERS)
    return()
  endif()
  set(source ${CMAKE_CURRENT_BINARY_DIR}/${name}.cpp)
  if(kind STREQUAL "PROGRAM")  # executables are compiled as position-independent executables, libraries not
    file(CONFIGURE OUTPUT ${source} CONTENT "int main() { return 0; }\n")
    add_executable(${name} EXCLUDE_FROM_ALL ${source})
  else()
    file(CONFIGURE OUTPUT ${source} CONTENT "\n")
    add_library(${name} STATIC EXCLUDE_FROM_ALL ${source})
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  mlidar_warnings(${name})
  target_precompile_headers(${name} PRIVATE ${ARG_HEADERS})
endfunction()

# mlidar_precompile(TARGET HOST): TARGET's files start from HOST's precompiled header.
function(mlidar_precompile target host)
  if(MLIDAR_PRECOMPILE_HEADERS)
    target_precompile_headers(${target} REUSE_FROM ${host})
  endif()
endfunction()

# mlidar_library(NAME SOURCES... DEPS ... [OWN_FLAGS]): one library per layer, named mlidar_NAME. OWN_FLAGS: a library
# compiled with flags of its own, which the shared precompiled header does not fit.
function(mlidar_library name)
  cmake_parse_arguments(ARG "OWN_FLAGS" "" "SOURCES;DEPS" ${ARGN})
  add_library(mlidar_${name} ${ARG_SOURCES})
  add_library(mlidar::${name} ALIAS mlidar_${name})
  target_include_directories(mlidar_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(mlidar_${name} PUBLIC ${ARG_DEPS})
  mlidar_warnings(mlidar_${name})
  if(NOT ARG_OWN_FLAGS)
    mlidar_precompile(mlidar_${name} mlidar_pch_library)
  endif()
endfunction()

# mlidar_test(NAME SOURCES... DEPS ... [OWN_FLAGS]): one GoogleTest program registered with ctest (OWN_FLAGS: as for
# mlidar_library).
# Tests find the shared real data and the mlidar executable through compiled-in
# defaults (MLIDAR_TEST_SHARED_DATA, MLIDAR_TEST_BIN); the environment variables
# MLIDAR_SHARED_DATA and MLIDAR_BIN override them.
function(mlidar_test name)
  cmake_parse_arguments(ARG "OWN_FLAGS" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  mlidar_warnings(${name})
  if(NOT ARG_OWN_FLAGS)
    mlidar_precompile(${name} mlidar_pch_test)
  endif()
  target_compile_definitions(${name} PRIVATE
    MLIDAR_TEST_SHARED_DATA="${MLIDAR_SHARED_DATA}" MLIDAR_TEST_BIN="$<TARGET_FILE:mlidar>")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60)
endfunction()

set(MLIDAR_SHARED_DATA "${PROJECT_SOURCE_DIR}/../shared/data" CACHE PATH "Folder of the shared real LiDAR data")
