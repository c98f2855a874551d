# fuzz/fdp.cmake: finds libFuzzer's FuzzedDataProvider.h (WARPCHECK_FDP_HEADER) for the fuzz targets, their replay
# driver and the validation library's random geometries (which draw with the fuzz decoders).
# FuzzedDataProvider.h ships with clang's resource directory. Name the file itself rather than adding that
# directory to the include path: its stddef.h breaks GCC.
file(GLOB WARPCHECK_FDP_CANDIDATES /usr/lib/llvm-*/lib/clang/*/include/fuzzer/FuzzedDataProvider.h
     /usr/lib/clang/*/include/fuzzer/FuzzedDataProvider.h)
find_file(WARPCHECK_FDP_HEADER fuzzer/FuzzedDataProvider.h HINTS ${WARPCHECK_FDP_CANDIDATES} NO_DEFAULT_PATH)
if(NOT WARPCHECK_FDP_HEADER AND WARPCHECK_FDP_CANDIDATES)
  list(GET WARPCHECK_FDP_CANDIDATES -1 WARPCHECK_FDP_HEADER)
endif()
if(NOT WARPCHECK_FDP_HEADER)
  message(FATAL_ERROR "fuzzer/FuzzedDataProvider.h not found (install clang and libclang-rt-14-dev: scripts/setup.sh)")
endif()
