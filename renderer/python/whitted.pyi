# SPDX-License-Identifier: MIT
"""Type stubs for the Python module `whitted` (renderer/python/whitted_module.cpp; docs/library.md).

tests/python/test_stub.py checks that every public name of the built module is here and every name
here is in the module, and that each function's parameter names, order, keyword-only marks and
defaults agree with pybind11's own signature; keep them in step with whitted_module.cpp.
"""
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

# A point, direction or colour: three numbers (a list or tuple).
_Vec3 = Sequence[float]
# A material: the keys ka, kd, ks, km (a number or three) and p (a number).
_Material = Dict[str, Union[float, Sequence[float]]]
_Progress = Callable[[int, int], object]
_Crop = Tuple[int, int, int, int]

def version() -> str:
    """The library's version (the same as whitted.__version__)."""
    ...

class Error(RuntimeError):
    """A bad scene, option or file: str() is 'FILE:LINE:COL: message'."""

    message: str
    file: str
    line: int
    column: int
    kind: str
    """'bad_input', 'failure' or 'cancelled'."""

class Scene:
    """A loaded, validated scene (whitted.load, whitted.loads, SceneBuilder.build)."""

    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def samples(self) -> int: ...
    @property
    def max_depth(self) -> int: ...
    @property
    def path(self) -> str: ...
    @property
    def layers(self) -> List[str]:
        """render.layers as written in the scene (empty: none asked for)."""
        ...

def load(
    path: str,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    samples: Optional[int] = None,
    max_depth: Optional[int] = None,
    intersection: Optional[str] = None,
) -> Scene:
    """Read and validate a scene file (YAML/JSON, course .xml, NFF); raises Error naming FILE:LINE:COL.
    The keywords replace the file's settings, as `whitted render --width ...` does."""
    ...

def loads(
    text: str,
    name: str = "<string>",
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    samples: Optional[int] = None,
    max_depth: Optional[int] = None,
    intersection: Optional[str] = None,
) -> Scene:
    """Read and validate a scene from a string; `name` (its extension) picks the format and stands
    for the file in messages. Overrides as for load."""
    ...

def render(
    scene: Scene, threads: int = 0, progress: Optional[_Progress] = None, crop: Optional[_Crop] = None
) -> npt.NDArray[np.float32]:
    """Render the beauty: float32 H x W x 3, linear, the EXR's pixels bit for bit. progress(done, total)
    is called from this thread; an exception it raises (or Ctrl-C) cancels the render and propagates.
    crop=(x, y, width, height) renders only that window."""
    ...

def render_layers(
    scene: Scene,
    layers: List[str] = [],
    threads: int = 0,
    progress: Optional[_Progress] = None,
    crop: Optional[_Crop] = None,
) -> Dict[str, npt.NDArray[np.float32]]:
    """Render with render layers (docs/layers.md; empty: the scene's render.layers): 'beauty' and one
    array per layer (H x W x channels)."""
    ...

def write_image(
    image: npt.ArrayLike,
    path: str,
    half: bool = False,
    exr_compression: str = "",
    bit_depth: int = 0,
    ocio_config: str = "",
    display: str = "",
    view: str = "",
) -> None:
    """Write an H x W x 3 linear image as `whitted render` does: .exr linear, .png/.jpg/.tif through
    the display transform (the built-in config's, or the OpenColorIO config's)."""
    ...

def to_povray(scene: Scene) -> str:
    """The scene as POV-Ray 3.7 SDL."""
    ...

def write_povray(scene: Scene, path: str) -> str:
    """Write the .pov file and its .ini; returns the .ini's path."""
    ...

class CheckResult:
    """The outcome of whitted.check; truthy when passed."""

    @property
    def passed(self) -> bool: ...
    @property
    def fraction_within(self) -> float:
        """Share of pixels within tolerance."""
        ...
    @property
    def max_error_codes(self) -> float:
        """Largest error of any channel, in 16-bit codes."""
        ...
    @property
    def psnr(self) -> float:
        """dB."""
        ...
    @property
    def failures(self) -> List[str]: ...
    @property
    def verdict(self) -> str:
        """The verdict line `whitted check` prints last."""
        ...
    def __bool__(self) -> bool: ...

def check(
    path: str,
    threads: int = 0,
    tolerance: float = 2.0,
    min_fraction: float = 0.999,
    max_error: float = 64.0,
    report_dir: str = "",
    quiet: bool = True,
    *,
    layers: List[str] = [],
    terms: bool = False,
    povray_image: str = "",
    exposure: float = 1.0,
) -> CheckResult:
    """`whitted check`: render the scene file with Whitted and with POV-Ray 3.7 and compare pixel by
    pixel (tolerances in 16-bit codes). layers: render with these and compare the beauty, then the sum
    of the colour layers; terms: term by term; povray_image: a stored POV-Ray 16-bit PNG instead of
    running POV-Ray, made at `exposure`. Ctrl-C ends POV-Ray and raises KeyboardInterrupt."""
    ...

class Comparison:
    """The outcome of whitted.compare_image_files; truthy when passed."""

    @property
    def passed(self) -> bool: ...
    @property
    def first_meaning(self) -> str:
        """What the first file was read as, e.g. 'linear Rec.709 (EXR)'; empty when the sizes differ."""
        ...
    @property
    def second_meaning(self) -> str: ...
    @property
    def fraction_within(self) -> float:
        """Share of pixels within tolerance."""
        ...
    @property
    def max_error_codes(self) -> float:
        """Largest error of any channel, in 16-bit codes (inf with NaN/Inf values)."""
        ...
    @property
    def rms_error(self) -> float:
        """Root mean square error, linear units."""
        ...
    @property
    def failures(self) -> List[str]:
        """The rules broken, e.g. 'cap (max 1000.0 codes > 64)'."""
        ...
    @property
    def verdict(self) -> str:
        """'PASS A vs B: ...' or 'FAIL A vs B: ...', as `whitted compare` prints."""
        ...
    def __bool__(self) -> bool: ...

def compare_image_files(
    first: str,
    second: str,
    tolerance: float = 2.0,
    min_fraction: float = 0.999,
    max_error: float = 64.0,
    clip: bool = False,
) -> Comparison:
    """`whitted compare A B`: two image files, each turned into linear Rec.709 from its colour metadata,
    compared channel by channel (tolerances in 16-bit codes; clip: both clipped to [0, 1] first)."""
    ...

def explain(scene: Scene, x: int, y: int, threads: int = 0) -> Dict[str, Any]:
    """`whitted explain SCENE --pixel X,Y --json`: every term of pixel (x, y)'s equation as a dict
    (docs/explain.schema.json)."""
    ...

def explain_text(scene: Scene, x: int, y: int, summary: bool = False, threads: int = 0) -> str:
    """`whitted explain SCENE --pixel X,Y` (summary: `--summary`): the text the program prints."""
    ...

def describe_colour_config(ocio_config: str = "") -> str:
    """`whitted colour --list`: each display and view of the config (empty: $OCIO, else the built-in)."""
    ...

def write_colour_config(path: str) -> None:
    """`whitted colour --write-config PATH`: the built-in OpenColorIO config, for other programs; never
    written through a symbolic link."""
    ...

class SceneBuilder:
    """A scene built in code; each method returns the builder."""

    def __init__(self) -> None: ...
    def image(self, width: int, height: int, samples: int = 1) -> SceneBuilder: ...
    def background(self, color: _Vec3) -> SceneBuilder: ...
    def camera(self, eye: _Vec3, look_at: _Vec3, up: _Vec3 = [0.0, 1.0, 0.0], fov: float = 45.0) -> SceneBuilder:
        """fov: the horizontal field of view, degrees."""
        ...
    def ambient(self, intensity: _Vec3) -> SceneBuilder:
        """Ia (default 1, 1, 1)."""
        ...
    def max_depth(self, depth: int) -> SceneBuilder:
        """Mirror bounces (default 5)."""
        ...
    def point_light(self, position: _Vec3, intensity: _Vec3) -> SceneBuilder: ...
    def directional_light(self, direction: _Vec3, intensity: _Vec3) -> SceneBuilder: ...
    def sphere(self, center: _Vec3, radius: float, material: _Material) -> SceneBuilder: ...
    def plane(self, point: _Vec3, normal: _Vec3, material: _Material) -> SceneBuilder: ...
    def box(self, min: _Vec3, max: _Vec3, material: _Material) -> SceneBuilder: ...
    def triangle(self, a: _Vec3, b: _Vec3, c: _Vec3, material: _Material) -> SceneBuilder: ...
    def build(self) -> Scene:
        """Validate and return the Scene (raises Error naming '<SceneBuilder>:CALL')."""
        ...
