# SPDX-License-Identifier: MIT
# The wheel's layout for `pip install .` (setup.py passes this file as
# CMAKE_PROJECT_Whitted_INCLUDE; docs/library.md "pip"): site-packages/whitted.*.so beside
# site-packages/whitted.libs/ holding libwhitted.so.MAJOR.MINOR and the plug-in libwhitted_oiio.so,
# which libwhitted.so loads from its own folder. The module is linked with the RPATH it will have
# there, so the files setup.py copies into the wheel need no patching and carry no path of the
# build tree; `cmake --install` layouts are left as renderer/python/CMakeLists.txt sets them.
# The library gets no fallback path to the build tree's plug-in (WHITTED_BUILD_PLUGIN_DIR, for the
# tests): the wheel outlives its build directory, and without the path in its flags the library's
# objects are the same for any build directory, so ccache can reuse them.
# Deferred: the targets exist only once the whole top-level CMakeLists.txt has been read.
function(whitted_wheel_layout)
  set_target_properties(whitted_python PROPERTIES BUILD_WITH_INSTALL_RPATH ON INSTALL_RPATH "$ORIGIN/whitted.libs")
  get_target_property(definitions whitted_core COMPILE_DEFINITIONS)
  list(FILTER definitions EXCLUDE REGEX "^WHITTED_BUILD_PLUGIN_DIR=")
  set_target_properties(whitted_core PROPERTIES COMPILE_DEFINITIONS "${definitions}")
endfunction()
cmake_language(DEFER CALL whitted_wheel_layout)
