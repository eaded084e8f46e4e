# SPDX-License-Identifier: MIT
# pov.far_mesh_<T>: Whitted renders SCENE (far_mesh.yaml moved by T, exactly) and ORIGIN
# (far_mesh.yaml, which pov.far_mesh checks against POV-Ray) and the two images must agree to
# 2/65535 on every pixel (`compare --min-fraction 1`). Far from the origin POV-Ray's own image
# changes, so it cannot be the reference there (docs/validation.md, Far from the origin).
foreach(var WHITTED SCENE ORIGIN OUT_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "far_placement.cmake needs -D${var}=...")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT_DIR})
foreach(pair "${SCENE};far" "${ORIGIN};origin")
  list(GET pair 0 scene)
  list(GET pair 1 name)
  execute_process(COMMAND ${WHITTED} render ${scene} -o ${OUT_DIR}/${name}.exr RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "whitted render ${scene} failed (${rc})")
  endif()
endforeach()
execute_process(COMMAND ${WHITTED} compare ${OUT_DIR}/origin.exr ${OUT_DIR}/far.exr --min-fraction 1
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the image far from the origin differs from the one at the origin (${rc})")
endif()
