# Runs the cdcr executable once and checks its exit code and output.
#
#   cmake -DCDCR_CLI=<path> -DCLI_ARGS=<args separated by |> -DEXPECT_EXIT=<code>
#         [-DEXPECT_STDOUT=<regex>] [-DEXPECT_STDERR=<regex>] -P run_cli.cmake
#
# EXPECT_STDOUT unset: stdout must be empty (an error leaves nothing partial).
# EXPECT_STDERR unset: stderr must be empty; set: stderr must be exactly one
# line, and that line (without its newline) must match the regex.
# Arguments are joined with | because a CMake list would be split apart on
# its way through add_test().

foreach(required CDCR_CLI EXPECT_EXIT)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "run_cli.cmake: ${required} is not set")
  endif()
endforeach()

string(REPLACE "|" ";" arguments "${CLI_ARGS}")
execute_process(
  COMMAND "${CDCR_CLI}" ${arguments}
  RESULT_VARIABLE exit_code
  OUTPUT_VARIABLE stdout
  ERROR_VARIABLE stderr)

set(failures "")
if(NOT exit_code STREQUAL EXPECT_EXIT)
  string(APPEND failures "exit code ${exit_code}, expected ${EXPECT_EXIT}\n")
endif()

# The text in the variable `text_var` must match the regex in `expected_var`
# or, where that is not set, be empty; what does not is added to `failures`.
function(expect_stream name text_var expected_var)
  if(DEFINED ${expected_var})
    if(NOT ${text_var} MATCHES "${${expected_var}}")
      string(APPEND failures "${name} does not match: ${${expected_var}}\n")
    endif()
  elseif(NOT ${text_var} STREQUAL "")
    string(APPEND failures "${name} should be empty\n")
  endif()
  set(failures "${failures}" PARENT_SCOPE)
endfunction()

expect_stream(stdout stdout EXPECT_STDOUT)
if(NOT DEFINED EXPECT_STDERR)
  expect_stream(stderr stderr EXPECT_STDERR)
elseif(NOT stderr MATCHES "^[^\n]*\n$")
  string(APPEND failures "stderr should be exactly one line\n")
else()
  string(REGEX REPLACE "\n$" "" stderr_line "${stderr}")
  expect_stream(stderr stderr_line EXPECT_STDERR)
endif()

if(NOT failures STREQUAL "")
  list(JOIN arguments " " command_line)
  message(FATAL_ERROR "cdcr ${command_line}\n${failures}--- stdout ---\n${stdout}--- stderr ---\n${stderr}")
endif()
