# SPDX-License-Identifier: MIT
"""The CMake half of `pip install .` (pyproject.toml holds the metadata; docs/library.md "pip").

The extension `whitted` is not compiled by setuptools: CMake builds the targets whitted_python and
whitted_oiio (Release, no tests, for this interpreter), and build_ext copies into the wheel
    whitted.<EXT_SUFFIX>              the module, RPATH $ORIGIN/whitted.libs (cmake/WhittedWheel.cmake)
    whitted.libs/libwhitted.so.M.m    the library, under its SONAME
    whitted.libs/libwhitted_oiio.so   the plug-in libwhitted.so loads from its own folder
    whitted.libs/libwhitted_{exr,tiff,jpeg}.so   the writers of those formats, plug-ins likewise
    whitted.libs/libwhitted_ocio.so   OpenColorIO's display transform, a plug-in likewise
    whitted.pyi                       the type stubs
Everything is built under $WHITTED_PIP_BUILD_DIR (default: build-pip/ here), never in build/.
CMake options can be added in $CMAKE_ARGS; the build's parallelism is $CMAKE_BUILD_PARALLEL_LEVEL
(default: every core). A CMake $CMAKE_GENERATOR or a compiler launcher
($CMAKE_CXX_COMPILER_LAUNCHER, e.g. ccache) in the environment is used as CMake uses it.
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
# The image writers built as plug-ins (renderer/src/output/format_plugins.h) and the
# OpenColorIO display transform (renderer/src/output/ocio_plugin.h).
PLUGIN_FORMATS = ("exr", "tiff", "jpeg", "ocio")
BUILD = os.path.abspath(os.environ.get("WHITTED_PIP_BUILD_DIR") or os.path.join(ROOT, "build-pip"))
CMAKE_BUILD = os.path.join(BUILD, "cmake")


def fail(message):
    # SystemExit with a text: the build backend exits 1 and pip shows the text with its error.
    raise SystemExit("whitted: " + message)


def project_version():
    """project(Whitted VERSION x.y.z) in CMakeLists.txt: the one place the version is written."""
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        match = re.search(r"project\(\s*Whitted\s+VERSION\s+([0-9]+(?:\.[0-9]+)*)", f.read())
    if not match:
        fail(f"{os.path.join(ROOT, 'CMakeLists.txt')}: no 'project(Whitted VERSION x.y.z)' to take the version from")
    return match.group(1)


def run(step, command):
    print("whitted: " + shlex.join(command), flush=True)
    try:
        subprocess.run(command, check=True)
    except FileNotFoundError:
        fail(f"{step}: '{command[0]}' not found; install CMake 3.25 or newer (apt-get install cmake)")
    except subprocess.CalledProcessError as error:
        fail(f"CMake {step} failed (exit {error.returncode}); its messages are above. "
             f"Build directory: {CMAKE_BUILD}. Extra CMake options go in CMAKE_ARGS.")


class CMakeBuild(build_ext):
    def run(self):
        configure = ["cmake", "-S", ROOT, "-B", CMAKE_BUILD,
                     "-DCMAKE_BUILD_TYPE=Release",
                     "-DWHITTED_BUILD_TESTS=OFF", "-DWHITTED_BUILD_BENCHMARKS=OFF", "-DWHITTED_BUILD_PYTHON=ON",
                     "-DPython3_EXECUTABLE=" + sys.executable, "-DPython_EXECUTABLE=" + sys.executable,
                     "-DCMAKE_PROJECT_Whitted_INCLUDE=" + os.path.join(ROOT, "cmake", "WhittedWheel.cmake")]
        # Ninja when there is one, unless CMAKE_GENERATOR says otherwise or the build directory
        # already has its generator (CMake refuses another).
        if (not os.environ.get("CMAKE_GENERATOR") and shutil.which("ninja")
                and not os.path.exists(os.path.join(CMAKE_BUILD, "CMakeCache.txt"))):
            configure += ["-G", "Ninja"]
        configure += shlex.split(os.environ.get("CMAKE_ARGS", ""))
        run("configure", configure)
        build = ["cmake", "--build", CMAKE_BUILD, "--target", "whitted_python", "whitted_oiio"] + [
            f"whitted_{fmt}" for fmt in PLUGIN_FORMATS]
        if not os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):
            build += ["--parallel", str(os.cpu_count() or 1)]
        run("build", build)

        module = "whitted" + sysconfig.get_config_var("EXT_SUFFIX")
        library = os.path.join(CMAKE_BUILD, "lib", "libwhitted.so")
        if not os.path.islink(library):
            fail(f"{library} is not the link to libwhitted.so.MAJOR.MINOR that CMake makes")
        soname = os.readlink(library)  # libwhitted.so.0.2, the name the module asks for
        libs = os.path.join(self.build_lib, "whitted.libs")
        os.makedirs(libs, exist_ok=True)
        copies = [(os.path.join(CMAKE_BUILD, "python", module), self.get_ext_fullpath("whitted")),
                  (os.path.join(CMAKE_BUILD, "lib", soname), os.path.join(libs, soname)),
                  (os.path.join(CMAKE_BUILD, "lib", "libwhitted_oiio.so"), os.path.join(libs, "libwhitted_oiio.so")),
                  (os.path.join(ROOT, "renderer", "python", "whitted.pyi"), os.path.join(self.build_lib, "whitted.pyi"))]
        copies += [(os.path.join(CMAKE_BUILD, "lib", f"libwhitted_{fmt}.so"), os.path.join(libs, f"libwhitted_{fmt}.so"))
                   for fmt in PLUGIN_FORMATS]
        for source, target in copies:
            if not os.path.isfile(source):
                fail(f"the build made no {source}")
            shutil.copyfile(source, target)  # the file itself, not a symbolic link
            shutil.copymode(source, target)


os.makedirs(BUILD, exist_ok=True)
setup(
    version=project_version(),
    ext_modules=[Extension("whitted", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # No Python packages: the folders here (renderer/, tests/, ...) are not to be discovered.
    packages=[],
    py_modules=[],
    zip_safe=False,
    options={"build": {"build_base": os.path.join(BUILD, "setuptools")}, "egg_info": {"egg_base": BUILD}},
)
