# SPDX-License-Identifier: MIT
# Turns a text file into a C++ header holding it as one raw string literal, so that a file the
# program writes out (the report viewer's script) is kept and edited as the file it is.
# cmake -DINPUT=file -DOUTPUT=header.h -DNAME=identifier -P embed_text.cmake
file(READ "${INPUT}" text)
string(FIND "${text}" ")whitted_embed\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} holds the raw-string delimiter )whitted_embed\"")
endif()
file(WRITE "${OUTPUT}.tmp" "// Generated from ${INPUT} by cmake/embed_text.cmake; do not edit.\n#pragma once\n"
     "inline constexpr const char* ${NAME} = R\"whitted_embed(${text})whitted_embed\";\n")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.tmp")
