# cmake -DCDCR= -DOUT_DIR= -DREFERENCE= -P train_with_other_kernels.cmake
# The demo's model (700 samples of the simulated robot, seed 1, 50 held out)
# made the way qemu.golden makes it, but with the numerical kernels another
# x86-64 CPU would get: OpenBLAS forced to its SSE3 (Prescott) kernels, and
# glibc's maths without its FMA and AVX variants. Both run on every x86-64
# CPU. The simulator's and the trainer's last bits change with them, and with
# those the optimiser's path: the image is a different model of the same
# robot, on which the demo model's tests must hold as they do on the build's.
foreach(variable CDCR OUT_DIR REFERENCE)
  if(NOT ${variable})
    message(FATAL_ERROR "train_with_other_kernels.cmake: ${variable} is not set")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT_DIR})
set(other_kernels OPENBLAS_CORETYPE=Prescott GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX,-AVX2,-FMA,-FMA4)

function(run)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${other_kernels} ${ARGN} RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "failed (${status}): ${command}")
  endif()
endfunction()

run(${CDCR} simulate --samples 700 --seed 1 --out ${OUT_DIR}/robot.csv)
run(${CDCR} train --data ${OUT_DIR}/robot.csv --holdout 50 --out ${OUT_DIR}/model.img)
# Whether the kernels changed the model is worth knowing, not a failure:
# the training does depend on them, and the tests' floors allow for it.
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT_DIR}/model.img ${REFERENCE}
                RESULT_VARIABLE differs OUTPUT_QUIET ERROR_QUIET)
if(differs)
  message("the image trained with other kernels differs from the build's")
else()
  message("the image trained with other kernels is the build's, byte for byte")
endif()
