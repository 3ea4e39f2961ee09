# cmake -DSOURCE_DIR= -DWORK_DIR= -DCDCR= -DBUILD_DIR= [-DMODEL_IMAGE=model.img]
#       [-DTOOLCHAIN=<file> -DQEMU= -DMACHINE= -DCPU=] -P run_installed_example.cmake
# What a board integrator does, from a clean prefix:
#   1. install cdcr under WORK_DIR/prefix from the build BUILD_DIR as it is:
#      the host build, or with TOOLCHAIN a cross build of the tree made with
#      that toolchain file (the QEMU tests' own, which has built the
#      libraries that install: cdcr_c_api, cdcr_cortexm, cdcr_mps2);
#   2. export the model image as C with `cdcr export --format c` (MODEL_IMAGE,
#      or one trained here on a small simulated data set);
#   3. configure firmware/examples/c_main_loop out of tree against the prefix
#      (CMAKE_PREFIX_PATH; a cross build with the toolchain file installed
#      there), build it;
#   4. run it, on the host or under QEMU: it must boot into RUN, print
#      compensated poses and PASS, and exit with 0.
foreach(variable SOURCE_DIR WORK_DIR CDCR BUILD_DIR)
  if(NOT ${variable})
    message(FATAL_ERROR "run_installed_example.cmake: ${variable} is not set")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(NOT status EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "failed (${status}): ${command}\n${output}")
  endif()
endfunction()

set(prefix ${WORK_DIR}/prefix)
set(example_build ${WORK_DIR}/example)
file(REMOVE_RECURSE ${prefix} ${example_build})
file(MAKE_DIRECTORY ${WORK_DIR})

# 1. The prefix.
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(installed include/cdcr/cdcr.h lib/cmake/cdcr/cdcrConfig.cmake)
  if(NOT EXISTS ${prefix}/${installed})
    message(FATAL_ERROR "cmake --install put no ${installed} under ${prefix}")
  endif()
endforeach()

# 2. The model.
if(NOT MODEL_IMAGE)
  set(MODEL_IMAGE ${WORK_DIR}/model.img)
  run(${CDCR} simulate --samples 200 --seed 5 --out ${WORK_DIR}/robot.csv)
  run(${CDCR} train --data ${WORK_DIR}/robot.csv --holdout 0 --out ${MODEL_IMAGE})
endif()
run(${CDCR} export --model ${MODEL_IMAGE} --format c --out ${WORK_DIR}/model_image.c)

# 3. The example, out of tree.
set(example_args -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
    -DCDCR_MODEL_IMAGE_C=${WORK_DIR}/model_image.c)
if(TOOLCHAIN)
  get_filename_component(toolchain_name ${TOOLCHAIN} NAME)
  list(APPEND example_args -DCMAKE_TOOLCHAIN_FILE=${prefix}/share/cdcr/toolchains/${toolchain_name})
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/firmware/examples/c_main_loop -B ${example_build} ${example_args})
run(${CMAKE_COMMAND} --build ${example_build} -j2)

# 4. Run it.
if(TOOLCHAIN)
  execute_process(
    COMMAND timeout 60 ${QEMU} -M ${MACHINE} -cpu ${CPU} -display none -monitor none -serial null
            -chardev stdio,id=sh0 -semihosting-config enable=on,target=native,chardev=sh0
            -kernel ${example_build}/c_main_loop.elf
    OUTPUT_VARIABLE output ERROR_VARIABLE output RESULT_VARIABLE status)
else()
  execute_process(COMMAND timeout 60 ${example_build}/c_main_loop
    OUTPUT_VARIABLE output ERROR_VARIABLE output RESULT_VARIABLE status)
endif()
message("${output}")
if(NOT status EQUAL 0)
  message(FATAL_ERROR "c_main_loop exited with status ${status}")
endif()
foreach(expected "state RUN\n" "mm \\(compensated\\)\n" "(^|\n)PASS\n")
  if(NOT output MATCHES "${expected}")
    message(FATAL_ERROR "c_main_loop's output does not match '${expected}'")
  endif()
endforeach()
