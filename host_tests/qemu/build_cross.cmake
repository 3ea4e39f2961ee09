# cmake -DSOURCE_DIR= -DBINARY_DIR= -DTOOLCHAIN= -DTARGETS= [-DGOLDEN_DIR=] [-DBUILD_TYPE=Release] -P build_cross.cmake
# Configures the cross build of the tree once and rebuilds TARGETS: the
# Cortex-M boards' (with GOLDEN_DIR, the golden model image linked into the
# programs) and the R5F board's (host_tests/zynqmp).
foreach(variable SOURCE_DIR BINARY_DIR TOOLCHAIN TARGETS)
  if(NOT ${variable})
    message(FATAL_ERROR "build_cross.cmake: ${variable} is not set")
  endif()
endforeach()

if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()
set(golden_args)
if(GOLDEN_DIR)
  set(golden_args -DCDCR_QEMU_GOLDEN_DIR=${GOLDEN_DIR} -DCDCR_MODEL_IMAGE_C=${GOLDEN_DIR}/cdcr_model_image.cpp)
endif()

execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BINARY_DIR} -DCMAKE_TOOLCHAIN_FILE=${TOOLCHAIN}
          -DCMAKE_BUILD_TYPE=${BUILD_TYPE} ${golden_args}
  RESULT_VARIABLE configure_result)
if(NOT configure_result EQUAL 0)
  message(FATAL_ERROR "configuring the cross build in ${BINARY_DIR} failed")
endif()

execute_process(
  COMMAND ${CMAKE_COMMAND} --build ${BINARY_DIR} --target ${TARGETS} -j2
  RESULT_VARIABLE build_result)
if(NOT build_result EQUAL 0)
  message(FATAL_ERROR "building ${TARGETS} in ${BINARY_DIR} failed")
endif()
