# SPDX-License-Identifier: MIT
# Runs a command that must fail in a given way (ctest cannot check an exit status other than 0):
#   cmake -DEXPECT_EXIT=2 "-DEXPECT_STDERR=regex" -P expect_failure.cmake -- COMMAND ARGS...
# Passes when the command exits with EXPECT_EXIT and its stderr matches EXPECT_STDERR.
set(command "")
set(collect OFF)
foreach(i RANGE ${CMAKE_ARGC})
  if(collect AND DEFINED CMAKE_ARGV${i})
    list(APPEND command "${CMAKE_ARGV${i}}")
  elseif("${CMAKE_ARGV${i}}" STREQUAL "--")
    set(collect ON)
  endif()
endforeach()
if(NOT command OR NOT DEFINED EXPECT_EXIT)
  message(FATAL_ERROR "usage: cmake -DEXPECT_EXIT=N [-DEXPECT_STDERR=regex] -P expect_failure.cmake -- COMMAND...")
endif()
execute_process(COMMAND ${command} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("exit status ${status}\nstdout:\n${out}\nstderr:\n${err}")
if(NOT "${status}" STREQUAL "${EXPECT_EXIT}")
  message(FATAL_ERROR "expected exit status ${EXPECT_EXIT}, got ${status}")
endif()
if(DEFINED EXPECT_STDERR AND NOT err MATCHES "${EXPECT_STDERR}")
  message(FATAL_ERROR "stderr does not match '${EXPECT_STDERR}'")
endif()
