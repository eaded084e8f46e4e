# SPDX-License-Identifier: MIT
# One image test (run by ctest through `cmake -P`): render SCENE with Whitted and compare it
# with REFERENCE, POV-Ray's own 16-bit PNG of the converted scene, made at EXPOSURE by
# update_references.sh, without running POV-Ray:
#
#   cmake -DWHITTED=<whitted> -DSCENE=<yaml> -DREFERENCE=<png> -DEXPOSURE=<e> -DSHA256=<hex>
#         -DOUT_DIR=<dir> -P compare_image.cmake
#
# The comparison is `whitted check --povray-image`, i.e. the very one the pov tier makes with a
# live POV-Ray (exposure, n x n block averaging for image.samples > 1, size, channels, NaN/Inf)
# and the project's pass rule with its defaults: 2/65535 per channel on >= 99.9 % of pixels,
# no channel off by more than 64 codes (docs/validation.md, "The pass rule"). No tolerance of
# this tier's own. SHA256 (from ref/references.txt) proves the file is the one POV-Ray wrote.
#
# With -DLAYERS=<list> Whitted renders with those render layers (`check --layers`), so the
# beauty compared is the float sum of the colour layers (docs/layers.md).
#
# OUT_DIR keeps check's report (ours.png, povray.png, diff.png, metrics.json, report.html).

foreach(var WHITTED SCENE REFERENCE EXPOSURE SHA256 OUT_DIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "compare_image.cmake: -D${var}=... is required (for a reference without a row in "
                        "ref/references.txt, re-make it with tests/image/update_references.sh)")
  endif()
endforeach()
if(NOT EXISTS "${REFERENCE}")
  message(FATAL_ERROR "no reference image ${REFERENCE}; make it with tests/image/update_references.sh")
endif()
file(SHA256 "${REFERENCE}" actual_sha)
if(NOT actual_sha STREQUAL SHA256)
  message(FATAL_ERROR "${REFERENCE} is not the file POV-Ray wrote (SHA-256 ${actual_sha}, "
                      "ref/references.txt says ${SHA256}); re-make it with tests/image/update_references.sh")
endif()

file(REMOVE_RECURSE "${OUT_DIR}")  # an earlier failure's report would mislead
# WHITTED_POVRAY points nowhere: should anything try to run POV-Ray, the test fails instead of
# quietly depending on it. This tier runs where POV-Ray is not installed.
set(layer_arguments)
if(DEFINED LAYERS AND NOT LAYERS STREQUAL "")
  set(layer_arguments --layers "${LAYERS}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env WHITTED_POVRAY=/nonexistent/povray
                        "${WHITTED}" check "${SCENE}" --povray-image "${REFERENCE}" --exposure "${EXPOSURE}"
                        --report "${OUT_DIR}" ${layer_arguments}
                RESULT_VARIABLE check_result)
if(NOT check_result EQUAL 0)
  message(FATAL_ERROR "whitted check against the stored POV-Ray image failed (exit ${check_result}); "
                      "see ${OUT_DIR}/report.html")
endif()
