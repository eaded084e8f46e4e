# SPDX-License-Identifier: MIT
# Every dependency comes from Debian 12's packages (scripts/setup installs them); the quirks
# worked around here are described in docs/building.md.

find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
# libyaml (libyaml-dev): the YAML parser behind the scene reader's fast scanner (yaml_tree.cpp).
pkg_check_modules(LIBYAML REQUIRED IMPORTED_TARGET yaml-0.1)
find_package(embree 3 CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(fmt CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(OpenImageIO CONFIG REQUIRED)
find_package(OpenEXR CONFIG REQUIRED)
find_package(Imath CONFIG REQUIRED)
find_package(PNG REQUIRED)
find_package(JPEG REQUIRED)
find_package(TIFF REQUIRED)
find_package(ZLIB REQUIRED)
# The Cornell CS4620 course's XML scenes (renderer/src/scene/course_xml.cpp): expat reports
# the line and column of every element, which the error messages need.
find_package(EXPAT REQUIRED)
# cpp-httplib (libcpp-httplib-dev): the local web server of `whitted live` (docs/live.md). Debian
# builds it as a library with TLS, zlib and brotli on; pkg-config gives the matching definitions.
pkg_check_modules(CPPHTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)

# Quirk A: Debian built OpenImageIO with OpenCV, and its exported target names
# /usr/include/opencv4, which does not exist unless libopencv-dev (+417 MB) is installed.
foreach(property INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
  get_target_property(dirs OpenImageIO::OpenImageIO ${property})
  if(dirs)
    set(kept "")
    foreach(dir IN LISTS dirs)
      if(EXISTS "${dir}" OR dir MATCHES "^\\$<")
        list(APPEND kept "${dir}")
      endif()
    endforeach()
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${property} "${kept}")
  endif()
endforeach()

# Quirk B: OpenColorIO's CMake config computes a wrong prefix on Debian; pkg-config is right.
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO>=2.1)

if(WHITTED_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(WHITTED_BUILD_BENCHMARKS)
  find_package(benchmark CONFIG REQUIRED)
endif()
