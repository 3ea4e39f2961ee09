# cmake -DSOURCE_DIR= -DBINARY_DIR= -DTOOLCHAIN= -DTARGETS= -P build_r5f.cmake
# Configures the R5F cross build of the tree once and rebuilds TARGETS.
foreach(variable SOURCE_DIR BINARY_DIR TOOLCHAIN TARGETS)
  if(NOT ${variable})
    message(FATAL_ERROR "build_r5f.cmake: ${variable} is not set")
  endif()
endforeach()

execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BINARY_DIR} -DCMAKE_TOOLCHAIN_FILE=${TOOLCHAIN} -DCMAKE_BUILD_TYPE=Release
  RESULT_VARIABLE configure_result)
if(NOT configure_result EQUAL 0)
  message(FATAL_ERROR "configuring the R5F cross build in ${BINARY_DIR} failed")
endif()

execute_process(
  COMMAND ${CMAKE_COMMAND} --build ${BINARY_DIR} --target ${TARGETS} -j2
  RESULT_VARIABLE build_result)
if(NOT build_result EQUAL 0)
  message(FATAL_ERROR "building ${TARGETS} in ${BINARY_DIR} failed")
endif()
