# Compile options for marionette's own targets. Third-party headers come in as
# SYSTEM includes through their imported targets, so -Werror applies to our code only.

# -Werror is the project's own gate (the presets and CI turn it on); a plain
# `cmake -DCMAKE_BUILD_TYPE=Release` build by a packager or user must not fail on
# a new compiler's new warning (GCC 12's -Wrestrict false positive at -O3, say).
option(MARIONETTE_WERROR "Treat compiler warnings as errors (on in CMakePresets.json)" OFF)

add_library(marionette_options INTERFACE)
target_compile_options(marionette_options INTERFACE
  -Wall -Wextra -Wpedantic $<$<BOOL:${MARIONETTE_WERROR}>:-Werror>
  # Determinism (DESIGN.md): never fuse a*b+c into an FMA (and never enable
  # unsafe math: GCC's and Clang's defaults are IEEE-exact, so nothing to turn off),
  # so every build type and both compilers round identically.
  -ffp-contract=off)
target_compile_definitions(marionette_options INTERFACE
  GLM_FORCE_RADIANS GLM_FORCE_CTOR_INIT GLM_FORCE_XYZW_ONLY)

if(MARIONETTE_SANITIZE STREQUAL "address")
  target_compile_options(marionette_options INTERFACE
    -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  target_link_options(marionette_options INTERFACE -fsanitize=address,undefined)
elseif(MARIONETTE_SANITIZE STREQUAL "thread")
  target_compile_options(marionette_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(marionette_options INTERFACE -fsanitize=thread)
elseif(MARIONETTE_SANITIZE STREQUAL "fuzzer")
  # libFuzzer (clang only): coverage instrumentation plus ASan and UBSan on our
  # code; only the fuzz executables link libFuzzer's main (-fsanitize=fuzzer,
  # tests/fuzz/CMakeLists.txt).
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "MARIONETTE_SANITIZE=fuzzer needs clang++ (the fuzz preset uses clang++-14)")
  endif()
  target_compile_options(marionette_options INTERFACE
    -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  target_link_options(marionette_options INTERFACE -fsanitize=address,undefined)
elseif(NOT MARIONETTE_SANITIZE STREQUAL "")
  message(FATAL_ERROR "MARIONETTE_SANITIZE must be '', 'address', 'thread' or 'fuzzer'")
endif()
