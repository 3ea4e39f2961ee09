# cmake -DCDCR= -DMAKE_GOLDEN= -DOUT_DIR= [-DSAMPLES=700] -P make_golden_model.cmake
# The model the board programs carry, made the way a user makes one: the
# simulated robot's default data set (700 samples, 4 segments), 50 held out
# to validate, the exported model fitted on all 700; then the image and the
# host's golden results. SAMPLES makes a larger one (1,024 samples give the
# runtime's capacity).
foreach(variable CDCR MAKE_GOLDEN OUT_DIR)
  if(NOT ${variable})
    message(FATAL_ERROR "make_golden_model.cmake: ${variable} is not set")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT_DIR})
if(NOT SAMPLES)
  set(SAMPLES 700)
endif()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    string(REPLACE ";" " " command "${ARGN}")
    message(FATAL_ERROR "failed (${status}): ${command}")
  endif()
endfunction()

# Training takes seconds; keep a model whose data set has not changed.
# train_unless_unchanged(<data name> <image name> <simulate options...>)
function(train_unless_unchanged data image)
  run(${CDCR} simulate --samples ${SAMPLES} --seed 1 ${ARGN} --out ${OUT_DIR}/${data}.new)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT_DIR}/${data}.new ${OUT_DIR}/${data}
                  RESULT_VARIABLE changed)
  if(changed OR NOT EXISTS ${OUT_DIR}/${image})
    file(RENAME ${OUT_DIR}/${data}.new ${OUT_DIR}/${data})
    run(${CDCR} train --data ${OUT_DIR}/${data} --holdout 50 --out ${OUT_DIR}/${image})
  else()
    file(REMOVE ${OUT_DIR}/${data}.new)
  endif()
endfunction()

train_unless_unchanged(robot.csv model.img)
# A payload model of the same robot (tip payload 0 to 1 kg), for the cycle
# budget with a compliance block: cdcr train identifies the segments'
# compliance under the load and exports the block.
train_unless_unchanged(payload_robot.csv payload_model.img --payload-range 0,1)
# The same robot with three cables a segment, for the cycle budget of a
# three-cable robot (the image's cables block).
train_unless_unchanged(three_cable_robot.csv three_cable_model.img --cables-per-segment 3)
run(${MAKE_GOLDEN} ${OUT_DIR}/model.img ${OUT_DIR} ${OUT_DIR}/payload_model.img ${OUT_DIR}/three_cable_model.img)
