# A consumer project (examples/consumer: the CMakeLists.txt and the test the README prints) configured, built and
# run the way the README says, from outside this tree; run by ctest (tests consumer.install and
# consumer.add_subdirectory) as
#   cmake -DMODE=install|add_subdirectory -DSOURCE=<warpcheck source> -DBUILD=<warpcheck build> -DWORK=<scratch>
#         -DGENERATOR=... -DCXX=... -DLAUNCHER=... -DBUILD_TYPE=... -DWERROR=ON|OFF -P consumer_test.cmake
# install: `cmake --install BUILD --prefix WORK/prefix`, then the consumer finds it by CMAKE_PREFIX_PATH alone.
# add_subdirectory: the consumer adds SOURCE as a subdirectory (WARPCHECK_CLONE), building the library itself.
# Either way the consumer may not find PNG, OpenEXR or Google Benchmark (the tests', the report's and the
# benchmarks' needs, not the libraries'), and its own CMakeLists.txt sets no C++ standard: the targets carry C++20.
# WORK is kept between runs (only its CMakeCache.txt is removed), so that a rerun rebuilds only what changed.
foreach(v MODE SOURCE BUILD WORK GENERATOR CXX BUILD_TYPE)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "consumer_test.cmake: -D${v}=... missing")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " cmd)
    message(FATAL_ERROR "consumer test (${MODE}) failed: ${cmd}")
  endif()
endfunction()

set(args -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_DISABLE_FIND_PACKAGE_PNG=ON
         -DCMAKE_DISABLE_FIND_PACKAGE_OpenEXR=ON -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON)
if(LAUNCHER)
  list(APPEND args -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
if(MODE STREQUAL "install")
  file(REMOVE_RECURSE ${WORK}/prefix)
  run(${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix)
  list(APPEND args -DCMAKE_PREFIX_PATH=${WORK}/prefix)
elseif(MODE STREQUAL "add_subdirectory")
  list(APPEND args -DWARPCHECK_CLONE=${SOURCE} -DWARPCHECK_WARNINGS_AS_ERRORS=${WERROR})
else()
  message(FATAL_ERROR "consumer_test.cmake: MODE is install or add_subdirectory")
endif()

file(REMOVE ${WORK}/build/CMakeCache.txt)
run(${CMAKE_COMMAND} -S ${SOURCE}/examples/consumer -B ${WORK}/build -G ${GENERATOR} ${args})
run(${CMAKE_COMMAND} --build ${WORK}/build --parallel 2)
run(${CMAKE_CTEST_COMMAND} --test-dir ${WORK}/build --output-on-failure)
