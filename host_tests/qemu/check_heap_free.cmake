# cmake -DNM= -DELF= -P check_heap_free.cmake
# The link already fails on any allocator call (--wrap without __wrap_
# definitions); this checks the result independently of the link flags.
execute_process(COMMAND ${NM} --demangle ${ELF} OUTPUT_VARIABLE symbols RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${NM} ${ELF} failed")
endif()
string(REGEX MATCHALL "[^\n]* [TtWw] (_?_?(malloc|_malloc_r|calloc|_calloc_r|realloc|_realloc_r|free|_free_r|_sbrk|sbrk)|operator new[^\n]*)\n"
       offending "${symbols}")
if(offending)
  message(FATAL_ERROR "${ELF} contains allocator code:\n${offending}")
endif()
message("${ELF}: no malloc, free, _sbrk or operator new")
