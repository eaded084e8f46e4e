# SPDX-License-Identifier: MIT
# WHITTED_EMBREE_ISA=VALUE whitted render SCENE -o OUT must be a usage error: exit 2, a message
# containing MESSAGE, found before any work, and an existing OUT left exactly as it was.
#   cmake -DWHITTED=<whitted> -DSCENE=<yaml> -DOUT=<file> -DVALUE=<isa> -DMESSAGE=<text> -P usage_error.cmake
get_filename_component(out_dir "${OUT}" DIRECTORY)
file(MAKE_DIRECTORY "${out_dir}")
file(WRITE "${OUT}" "an earlier image\n")
execute_process(COMMAND ${CMAKE_COMMAND} -E env WHITTED_EMBREE_ISA=${VALUE} "${WHITTED}" render -q "${SCENE}" -o "${OUT}"
                RESULT_VARIABLE result ERROR_VARIABLE errors)
if(NOT result EQUAL 2)
  message(FATAL_ERROR "WHITTED_EMBREE_ISA=${VALUE}: expected exit 2, got ${result}\n${errors}")
endif()
string(FIND "${errors}" "${MESSAGE}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "WHITTED_EMBREE_ISA=${VALUE}: the message does not say '${MESSAGE}':\n${errors}")
endif()
file(READ "${OUT}" kept)
if(NOT kept STREQUAL "an earlier image\n")
  message(FATAL_ERROR "WHITTED_EMBREE_ISA=${VALUE}: ${OUT} was changed by a run that failed")
endif()
