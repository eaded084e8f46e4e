# SPDX-License-Identifier: MIT
# One image regression test (run by ctest through `cmake -P`): render SCENE with Whitted into
# OUT_DIR/ours.exr and compare it with the stored REFERENCE using idiff.
#
#   cmake -DWHITTED=<whitted> -DIDIFF=<idiff> -DSCENE=<yaml> -DREFERENCE=<exr> -DOUT_DIR=<dir>
#         -P compare_image.cmake
#
# Tolerance: -fail 2e-5 -failpercent 0.1 -hardfail 1e-3, in linear units (2e-5 ~ 1.3/65535).
# The renderer is deterministic on one machine (bit-identical whatever the thread count), but
# references are shared across compilers, standard libraries and CPUs: FMA contraction, libm's
# pow/sqrt and Embree's SIMD width change the last bits of a float, a few 1e-7 relative, which
# 2e-5 absorbs with a wide margin. Up to 0.1 % of pixels may exceed it (a handful of pixels at
# 96x72, e.g. where a last-bit difference moves a shadow-terminator or highlight by a hair),
# but no pixel may be off by more than 1e-3: that is a real change in what was rendered, and
# the reference has to be reviewed and re-rendered (update_references.sh), never loosened.
#
# On failure, OUT_DIR keeps ours.exr, a copy of the reference, diff.exr (signed ours - ref,
# unscaled) and diff_abs_x1000.exr (|ours - ref| x 1000: 1e-3 shows as 1.0), and their paths
# are printed.

foreach(var WHITTED IDIFF SCENE REFERENCE OUT_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "compare_image.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT IDIFF OR IDIFF MATCHES "NOTFOUND$")
  # Fail, never skip: a missing comparison tool must not look like a passing test.
  message(FATAL_ERROR "idiff (OpenImageIO's image comparison tool) was not found at configure time; "
                      "install the OpenImageIO tools (Debian: openimageio-tools) and re-run cmake")
endif()
if(NOT EXISTS "${REFERENCE}")
  message(FATAL_ERROR "no reference image ${REFERENCE}; create it with tests/image/update_references.sh "
                      "and review it against POV-Ray (whitted check) before committing it")
endif()

file(MAKE_DIRECTORY "${OUT_DIR}")
set(ours "${OUT_DIR}/ours.exr")
set(reference_copy "${OUT_DIR}/reference.exr")
set(diff "${OUT_DIR}/diff.exr")
set(diff_abs "${OUT_DIR}/diff_abs_x1000.exr")
# Leftovers of an earlier failure would be misleading next to a fresh image.
file(REMOVE "${ours}" "${reference_copy}" "${diff}" "${diff_abs}")

execute_process(COMMAND "${WHITTED}" render -q "${SCENE}" -o "${ours}" RESULT_VARIABLE render_result)
if(NOT render_result EQUAL 0)
  message(FATAL_ERROR "whitted render ${SCENE} failed (exit ${render_result})")
endif()

set(tolerance -fail 2e-5 -failpercent 0.1 -hardfail 1e-3)
execute_process(COMMAND "${IDIFF}" ${tolerance} "${ours}" "${REFERENCE}" RESULT_VARIABLE idiff_result)
# idiff: 0 = identical or below the warning threshold, 1 = warning only (within the failure
# thresholds), 2 = failure, 3 = different sizes, 4 = a file could not be read.
if(idiff_result EQUAL 0 OR idiff_result EQUAL 1)
  return()
endif()

list(JOIN tolerance " " tolerance_text)
file(COPY_FILE "${REFERENCE}" "${reference_copy}")
execute_process(COMMAND "${IDIFF}" ${tolerance} -o "${diff}" "${ours}" "${REFERENCE}" OUTPUT_QUIET)
execute_process(COMMAND "${IDIFF}" ${tolerance} -abs -scale 1000 -o "${diff_abs}" "${ours}" "${REFERENCE}"
                OUTPUT_QUIET)
message(FATAL_ERROR
  "image differs from its reference (idiff exit ${idiff_result}; tolerance: ${tolerance_text})\n"
  "  ours:       ${ours}\n"
  "  reference:  ${reference_copy}   (stored: ${REFERENCE})\n"
  "  difference: ${diff}   (ours - reference)\n"
  "              ${diff_abs}   (|ours - reference| x 1000)\n"
  "If the change is intended, re-render with tests/image/update_references.sh and review the new "
  "reference against POV-Ray (whitted check) before committing it.")
