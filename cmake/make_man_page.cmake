# SPDX-License-Identifier: MIT
# whitted(1) from the program's own --help, so the manual says what the program does:
#   cmake -DPROGRAM=bin/whitted -DSOURCE_DIR=... -DVERSION=0.2.0 -DOUTPUT=whitted.1.in -P make_man_page.cmake
# The top-level help is the DESCRIPTION, each subcommand's help (without the footer every help
# repeats) a part of COMMANDS, the footer EXIT STATUS AND ENVIRONMENT. --help names docs/ and
# examples/ in the source checkout; here they become @WHITTED_DATADIR@, which the install step
# replaces with PREFIX/share/whitted of the prefix installed into (cmake/WhittedInstall.cmake).

foreach(variable PROGRAM SOURCE_DIR VERSION OUTPUT)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "make_man_page.cmake: -D${variable}=... is required")
  endif()
endforeach()

function(help_of out)
  # COLUMNS: CLI11 does not wrap, but the progress bar code reads it; a fixed environment keeps
  # the page the same on every machine.
  execute_process(COMMAND ${CMAKE_COMMAND} -E env COLUMNS=80 ${PROGRAM} ${ARGN} --help
                  OUTPUT_VARIABLE text RESULT_VARIABLE status ERROR_VARIABLE errors)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "make_man_page.cmake: '${PROGRAM} ${ARGN} --help' failed (${status}): ${errors}")
  endif()
  string(REPLACE "${SOURCE_DIR}" "@WHITTED_DATADIR@" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# Text as roff: backslashes escaped, '-' as a minus sign (so options copy and search as typed),
# each line led by the zero-width \& (a line starting with '.' or "'" would be a request), and
# no-fill so the help's own layout stays.
function(as_roff out text)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REPLACE "-" "\\-" text "${text}")
  string(REGEX REPLACE "\n+$" "" text "${text}")
  string(REPLACE "\n" "\n\\&" text "${text}")
  set(${out} ".nf\n\\&${text}\n.fi\n" PARENT_SCOPE)
endfunction()

help_of(top)
string(FIND "${top}" "\nExit status:" footer_at)
if(footer_at LESS 0)
  message(FATAL_ERROR "make_man_page.cmake: no 'Exit status:' footer in '${PROGRAM} --help'")
endif()
string(SUBSTRING "${top}" 0 ${footer_at} description)
math(EXPR footer_at "${footer_at} + 1")
string(SUBSTRING "${top}" ${footer_at} -1 footer)

# The subcommands: the lines of the "Subcommands:" list, first name of each ("colour, color").
string(REGEX MATCH "\nSubcommands:\n(  [^\n]*\n)+" list "${top}")
string(REGEX MATCHALL "\n  [a-z]+" names "${list}")
set(commands "")
foreach(name IN LISTS names)
  string(STRIP "${name}" name)
  help_of(help ${name})
  string(FIND "${help}" "\nExit status:" end)
  if(end GREATER 0)
    string(SUBSTRING "${help}" 0 ${end} help)
  endif()
  as_roff(body "${help}")
  string(APPEND commands ".SS \"whitted ${name}\"\n${body}")
endforeach()

as_roff(description "${description}")
as_roff(footer "${footer}")
file(WRITE "${OUTPUT}" ".\\\" Generated from whitted --help by cmake/make_man_page.cmake.
.TH WHITTED 1 \"\" \"Whitted ${VERSION}\" \"User Commands\"
.SH NAME
whitted \\- an offline ray tracer for the classic lecture shading model, checked against POV\\-Ray
.SH SYNOPSIS
.B whitted
.RI [ OPTIONS ]
.I SUBCOMMAND
.RI [ ARGUMENTS ]
.SH DESCRIPTION
${description}.SH COMMANDS
${commands}.SH EXIT STATUS AND ENVIRONMENT
${footer}.SH FILES
.TP
.I @WHITTED_DATADIR@/docs/
the reference: scene\\-format.md, cli.md, nff.md, course\\-format.md, layers.md, validation.md, and the
JSON Schemas scene.schema.json and explain.schema.json
.TP
.I @WHITTED_DATADIR@/examples/
example scenes, among them the lecture's (lecture/)
.SH SEE ALSO
.BR povray (1),
.BR blender (1)
")
