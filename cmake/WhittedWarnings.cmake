# SPDX-License-Identifier: MIT
# Warnings for our own targets (not for the libraries we include as SYSTEM headers).
add_library(whitted_warnings INTERFACE)
target_compile_options(whitted_warnings INTERFACE
  -Wall                 # the usual suspects
  -Wextra               # unused parameters, sign/enum mix-ups
  -Wpedantic            # stay within ISO C++
  -Wshadow              # a local hiding a member or outer name
  -Wnon-virtual-dtor    # polymorphic classes must destroy correctly
  -Wcast-align          # misaligned pointer casts
  -Wnull-dereference    # paths the optimiser can prove dereference null
  -Wdouble-promotion    # float silently widened: matters for a precision-matched renderer
  -Wimplicit-fallthrough
  -Wno-restrict         # GCC 12 false positives inside std::string operator+ (GCC bug 105329)
)
