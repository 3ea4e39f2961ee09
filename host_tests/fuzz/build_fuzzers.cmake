# Configures and builds the fuzz sub-project; run by the fuzz.build test.
#
#   cmake -DSOURCE_DIR=<host_tests/fuzz> -DBINARY_DIR=<dir> -DCXX=<clang++>
#         -DCDCR_SOURCE_DIR=<repo> -DGENERATOR=<generator> -P build_fuzzers.cmake

foreach(required SOURCE_DIR BINARY_DIR CXX CDCR_SOURCE_DIR GENERATOR)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "build_fuzzers.cmake: ${required} is not set")
  endif()
endforeach()

execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BINARY_DIR} -G ${GENERATOR}
          -DCMAKE_CXX_COMPILER=${CXX} -DCDCR_SOURCE_DIR=${CDCR_SOURCE_DIR} --log-level=WARNING
  RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "configuring the fuzz targets failed (${result})")
endif()

cmake_host_system_information(RESULT cores QUERY NUMBER_OF_LOGICAL_CORES)
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BINARY_DIR} --parallel ${cores} RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "building the fuzz targets failed (${result})")
endif()
