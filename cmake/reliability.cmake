# Reliability builds, clang only (README "Fuzzing and sanitizers"):
#   DEPOTWIN_SANITIZE=ON  every target built with AddressSanitizer and UndefinedBehaviorSanitizer
#                         (float-cast-overflow included); a finding aborts (scripts/sanitize.sh)
#   DEPOTWIN_FUZZ=ON      the same, plus libFuzzer's coverage instrumentation and the fuzz targets
#                         of tests/fuzz/ (scripts/fuzz.sh)
# Neither is part of the normal (GCC, Release) build.
option(DEPOTWIN_SANITIZE "Build everything with ASan + UBSan (clang)" OFF)
option(DEPOTWIN_FUZZ "Build the libFuzzer targets of tests/fuzz/ with ASan + UBSan (clang)" OFF)

if(DEPOTWIN_SANITIZE OR DEPOTWIN_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "DEPOTWIN_SANITIZE and DEPOTWIN_FUZZ need clang "
                        "(-DCMAKE_CXX_COMPILER=clang++): GCC has no libFuzzer, and its "
                        "-fsanitize=undefined leaves out float-cast-overflow")
  endif()
  # undefined behaviour (float-to-integer overflow included) and memory errors stop the program
  set(DEPOTWIN_SANITIZER_FLAGS -fsanitize=address,undefined,float-cast-overflow
                               -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_compile_options(${DEPOTWIN_SANITIZER_FLAGS})
  add_link_options(-fsanitize=address,undefined,float-cast-overflow)
  if(DEPOTWIN_FUZZ)
    # coverage feedback for libFuzzer in every library; the fuzz targets link its main
    add_compile_options(-fsanitize=fuzzer-no-link)
  endif()
endif()
