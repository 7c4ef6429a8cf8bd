# SPDX-License-Identifier: BSD-3-Clause
# The one place that gives every tofnav target its standard, warnings and sanitizers.

function(tofnav_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wconversion -Wshadow
                                           -Wnon-virtual-dtor -Wold-style-cast
                                           # Options are set with designated initialisers; the
                                           # fields left out keep their header defaults.
                                           -Wno-missing-field-initializers
                                           # clang's -Wconversion adds sign conversions; GCC's not
                                           $<$<CXX_COMPILER_ID:Clang>:-Wno-sign-conversion>
                                           # GCC 12 -O3 false positive on string concatenation
                                           # (GCC bug 105329)
                                           $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>
                                           # GCC 12 -O3 false positives on std::vector and
                                           # std::optional members of inlined option structs
                                           # (GCC bug 107138 and kin); real uninitialised reads
                                           # are caught by -Wuninitialized, UBSan and the fuzzers
                                           $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>)
  if(TOFNAV_PCH)
    # GCC 12 -O3 with the precompiled headers warns falsely on "literal" + std::string (memcpy
    # bounds in char_traits, GCC bug 105651) in files that build clean without them; the builds
    # without precompiled headers keep both warnings.
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-stringop-overflow>
                                             $<$<CXX_COMPILER_ID:GNU>:-Wno-array-bounds>)
  endif()
  if(TOFNAV_UNITY)
    # In a unity build every .cpp is included into a generated file, so GCC takes the private
    # state of a pimpl class (fields of types from the file's anonymous namespace) for a header
    # exporting them; with one .cpp per translation unit the warning does not arise.
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
  endif()
  if(TOFNAV_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(TOFNAV_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined
                                             -fno-sanitize-recover=all -fno-omit-frame-pointer)
    # TOFNAV_SANITIZED lets a test that is slow under the sanitizers leave the check to the
    # optimised pass.
    target_compile_definitions(${target} PRIVATE EIGEN_INITIALIZE_MATRICES_BY_NAN TOFNAV_SANITIZED)
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
  endif()
endfunction()

# Precompiled headers (TOFNAV_PCH): the standard library, Eigen and, for the tests, GoogleTest are
# parsed once per build instead of once per file (a unit-test file compiles in about 70 % of the
# time). Every library reuses one header built by tofnav_pch_lib, every unit test one built by
# tofnav_pch_test, so the flags of each group must stay the same; GCC's -Winvalid-pch (which
# CMake adds; an error under -Werror) and clang's own check say so if they drift. scripts/build.sh turns it on where there is no ccache (CI).
set(tofnav_pch_headers <algorithm> <array> <cmath> <cstddef> <cstdint> <filesystem> <functional>
    <limits> <memory> <numbers> <optional> <random> <span> <stdexcept> <string> <string_view>
    <utility> <vector> <Eigen/Core> <Eigen/Geometry>)

# Unity builds (TOFNAV_UNITY): the .cpp files of a library or of the program are compiled in
# batches of tofnav_unity_batch, each one translation unit, so that the headers (Eigen,
# nlohmann/json, CLI11) are parsed and their templates instantiated and optimised once per batch
# instead of once per file. Names in anonymous namespaces must therefore be unique within a
# library: the build itself says where two files of one batch collide. scripts/build.sh turns it
# on with the precompiled headers where there is no compiler cache.
set(tofnav_unity_batch 16)

# tofnav_use_unity(<target>): compiles <target> in unity batches when TOFNAV_UNITY is on.
function(tofnav_use_unity target)
  if(TOFNAV_UNITY)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${tofnav_unity_batch})
  endif()
endfunction()

# tofnav_use_pch(<target> lib|test): gives <target> the shared header of its group.
function(tofnav_use_pch target group)
  if(NOT TOFNAV_PCH)
    return()
  endif()
  set(host tofnav_pch_${group})
  if(NOT TARGET ${host})
    add_library(${host} OBJECT ${PROJECT_SOURCE_DIR}/cmake/pch_host.cpp)
    target_link_libraries(${host} PRIVATE Eigen3::Eigen)
    set(headers ${tofnav_pch_headers})
    if(group STREQUAL "lib")
      set_target_properties(${host} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    else()
      target_link_libraries(${host} PRIVATE GTest::gmock)
      target_include_directories(${host} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
      target_compile_definitions(${host} PRIVATE TOFNAV_DATA_DIR="${PROJECT_SOURCE_DIR}/data")
      list(APPEND headers <gtest/gtest.h> <gmock/gmock.h>)
    endif()
    tofnav_target_options(${host})
    target_precompile_headers(${host} PRIVATE ${headers})
  endif()
  target_precompile_headers(${target} REUSE_FROM ${host})  # CMake adds -Winvalid-pch for GCC
endfunction()

# tofnav_add_library(<module> SOURCES ... [DEPENDS ...] [PRIVATE_DEPENDS ...])
# Creates tofnav_<module> with the alias tofnav::<module>; headers are included as
# "tofnav/<module>/<file>.hpp" from src/.
function(tofnav_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  add_library(tofnav_${name} STATIC ${ARG_SOURCES})
  add_library(tofnav::${name} ALIAS tofnav_${name})
  target_include_directories(tofnav_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(tofnav_${name} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS})
  set_target_properties(tofnav_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  if(TOFNAV_TEST_MODULES)
    # Only what the chosen tests and the fuzzers link is built.
    set_target_properties(tofnav_${name} PROPERTIES EXCLUDE_FROM_ALL ON)
  endif()
  tofnav_target_options(tofnav_${name})
  tofnav_use_pch(tofnav_${name} lib)
  tofnav_use_unity(tofnav_${name})
endfunction()

# tofnav_add_test(<module> SOURCES ... [DEPENDS ...]): one GoogleTest binary per module.
function(tofnav_add_test name)
  if(NOT TOFNAV_BUILD_TESTS)
    return()
  endif()
  if(TOFNAV_TEST_MODULES AND NOT name IN_LIST TOFNAV_TEST_MODULES)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  add_executable(tofnav_${name}_test ${ARG_SOURCES})
  target_include_directories(tofnav_${name}_test PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_link_libraries(tofnav_${name}_test PRIVATE tofnav::${name} ${ARG_DEPENDS} GTest::gmock
                                                    GTest::gtest_main)
  target_compile_definitions(tofnav_${name}_test
                             PRIVATE TOFNAV_DATA_DIR="${PROJECT_SOURCE_DIR}/data")
  tofnav_target_options(tofnav_${name}_test)
  tofnav_use_pch(tofnav_${name}_test test)
  include(GoogleTest)
  gtest_discover_tests(tofnav_${name}_test DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 300)
endfunction()

# tofnav_add_benchmark(<name> SOURCES ... [DEPENDS ...])
function(tofnav_add_benchmark name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPENDS} benchmark::benchmark)
  tofnav_target_options(${name})
endfunction()

# tofnav_add_fuzzer(<name> SOURCES ... [DEPENDS ...]): libFuzzer target (clang only).
function(tofnav_add_fuzzer name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPENDS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPENDS})
  target_compile_options(${name} PRIVATE -fsanitize=fuzzer)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer)
  tofnav_target_options(${name})
endfunction()
