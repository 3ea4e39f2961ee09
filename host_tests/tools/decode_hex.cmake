# Decodes an Intel HEX file with objcopy and compares the bytes with the image
# it was exported from.
#
#   cmake -DOBJCOPY=<path> -DHEX=<file.hex> -DIMAGE=<file.img> -DDECODED=<out.bin> -P decode_hex.cmake

foreach(required OBJCOPY HEX IMAGE DECODED)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "decode_hex.cmake: ${required} is not set")
  endif()
endforeach()

execute_process(COMMAND "${OBJCOPY}" -I ihex -O binary "${HEX}" "${DECODED}" RESULT_VARIABLE result ERROR_VARIABLE errors)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "objcopy failed on ${HEX}: ${errors}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${DECODED}" "${IMAGE}" RESULT_VARIABLE different)
if(NOT different EQUAL 0)
  message(FATAL_ERROR "${HEX} does not decode to ${IMAGE}")
endif()
