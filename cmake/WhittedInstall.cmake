# SPDX-License-Identifier: MIT
# What `cmake --install` puts beside the program, the library and the Python module (their own
# install rules are in renderer/api, renderer/mpi and renderer/python), and the Debian package of
# it all (`scripts/package`, or `cpack` in the build directory; docs/building.md "Install"):
#   share/whitted/docs/, share/whitted/examples/   what --help and the man page name
#   share/doc/whitted/                             README.md, CHANGELOG.md, copyright
#   share/man/man1/whitted.1.gz                    generated from --help (cmake/make_man_page.cmake)
#   share/bash-completion/completions/whitted      renderer/app/whitted.bash
#   share/blender/scripts/addons/whitted_blender/  the Blender add-on (Debian's Blender reads
#                                                  /usr/share/blender/scripts/addons)

set(whitted_data_dir ${CMAKE_INSTALL_DATADIR}/whitted)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${whitted_data_dir}/docs)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${whitted_data_dir}/examples)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/whitted)
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/whitted RENAME copyright)
install(FILES ${PROJECT_SOURCE_DIR}/renderer/app/whitted.bash
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME whitted)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/plugins/blender/whitted_blender
        DESTINATION ${CMAKE_INSTALL_DATADIR}/blender/scripts/addons
        PATTERN __pycache__ EXCLUDE PATTERN "*.pyc" EXCLUDE)

# The man page: the help text now, the install prefix's data folder filled in when installed.
set(whitted_man_in ${PROJECT_BINARY_DIR}/man/whitted.1.in)
add_custom_command(
  OUTPUT ${whitted_man_in}
  COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:whitted> -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
          -DVERSION=${PROJECT_VERSION} -DOUTPUT=${whitted_man_in} -P ${PROJECT_SOURCE_DIR}/cmake/make_man_page.cmake
  DEPENDS whitted ${PROJECT_SOURCE_DIR}/cmake/make_man_page.cmake
  COMMENT "whitted.1 from whitted --help"
  VERBATIM)
add_custom_target(whitted_man_page ALL DEPENDS ${whitted_man_in})
install(CODE "
  file(READ \"${whitted_man_in}\" page)
  string(REPLACE \"@WHITTED_DATADIR@\" \"\${CMAKE_INSTALL_PREFIX}/${whitted_data_dir}\" page \"\${page}\")
  file(WRITE \"${PROJECT_BINARY_DIR}/man/whitted.1\" \"\${page}\")
  file(ARCHIVE_CREATE OUTPUT \"${PROJECT_BINARY_DIR}/man/whitted.1.gz\" PATHS \"${PROJECT_BINARY_DIR}/man/whitted.1\"
       FORMAT raw COMPRESSION GZip)")
install(FILES ${PROJECT_BINARY_DIR}/man/whitted.1.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

# ---- the Debian package: cpack -G DEB ------------------------------------------------------------
# Installed under /usr (so the library goes to /usr/lib/<multiarch>, the module to
# /usr/lib/python3/dist-packages); DESTDIR staging keeps the prefix /usr in the man page.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME whitted)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "Whitted maintainers <maintainers@whitted.invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "ray tracer for the classic lecture shading model, checked against POV-Ray")
# The long description; CPack puts the summary above it and indents it as debian/control wants.
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "Whitted renders the Cornell CS4620 lecture's model exactly: ambient, Lambertian
diffuse, Blinn-Phong highlights, hard shadows from many lights, mirror reflection and
refraction by recursive ray tracing. It reads its own YAML/JSON scenes, the course's
XML scenes and Eric Haines' NFF databases, writes colour-managed PNG, JPEG, TIFF and
EXR, and checks any scene pixel by pixel against POV-Ray 3.7 (whitted check).

This package holds the program, the C++ library with its headers, CMake and
pkg-config files, the Python module, the Blender add-on, the documentation and
example scenes.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_SET_DESTDIR ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_STRIP_FILES ON)
# The shared libraries' packages come from dpkg-shlibdeps; what it cannot see is named here:
# Embree, which the program and the library load when they first make a BVH
# (renderer/src/render/embree_library.cpp); the Python module's interpreter (it is built for
# this minor version) and NumPy, which it imports at run time.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libembree3-3 (>= 3.13)")
if(WHITTED_BUILD_PYTHON)
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS
         ", python3 (>= ${WHITTED_PYTHON_VERSION}), python3 (<< ${WHITTED_PYTHON_NEXT_VERSION}), python3-numpy")
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "povray")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "blender, openmpi-bin")
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
