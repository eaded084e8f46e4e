# SPDX-License-Identifier: MIT
# The suite's first render (ctest fixture whitted_renders): SCENE to OUT with Whitted, which
# must succeed. An abort here (e.g. an Embree assertion on packet lanes) is turned into a
# message that says what it means, and the render tests that depend on it are not run.
#   cmake -DWHITTED=<whitted> -DSCENE=<yaml> -DOUT=<exr> -P sanity.cmake
get_filename_component(out_dir "${OUT}" DIRECTORY)
file(MAKE_DIRECTORY "${out_dir}")
file(REMOVE "${OUT}")
execute_process(COMMAND "${WHITTED}" --version OUTPUT_VARIABLE version)
execute_process(COMMAND "${WHITTED}" render -q "${SCENE}" -o "${OUT}" RESULT_VARIABLE result
                ERROR_VARIABLE errors)
if(NOT result EQUAL 0 OR NOT EXISTS "${OUT}")
  message(FATAL_ERROR
    "The first render of the suite failed (exit: ${result}): ${SCENE}, a 37x23 image whose 4x4 "
    "packets are partly filled at its edges.\n${version}\n${errors}\n"
    "Every render test depends on this one and is not run. If the message is an Embree "
    "assertion, Embree read a lane Whitted did not fill; WHITTED_EMBREE_ISA=sse2|avx2|... "
    "narrows down which of Embree's code paths fails (docs/building.md).")
endif()
message(STATUS "${version}")
