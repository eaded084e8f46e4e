// SPDX-License-Identifier: MIT
#pragma once

// Scene format v1 → POV-Ray 3.7 SDL that renders the same image (docs/pov-model.md). The
// settings (camera, lights, image, render) come from the SceneDescription; the objects from the
// Scene that validate_scene or load_scene_file built from it, whose one walk of the description
// has folded the transforms, resolved the materials and read the mesh files: the SDL holds the
// numbers Whitted renders, and no file is read again here.

#include "scene/description.h"

#include <string>

namespace whitted {
struct Scene;
}

namespace whitted::pov {

struct ConvertOptions {
    /// Multiplies every light, the ambient light and the background (the image is linear in
    /// them, and a power of two keeps it exact). `whitted check` uses it to bring scenes whose
    /// values exceed 1 into a 16-bit PNG's range.
    double exposure = 1.0;
    /// Output image type written into the .ini: false = 16-bit linear PNG (+FN16
    /// File_Gamma=1.0, clips at 1), true = OpenEXR (+FE, half floats, unclipped).
    bool hdr_output = false;
};

/// The whole SDL scene: `scene`'s settings and `built`'s objects (`built` is validate_scene(scene),
/// or the Scene load_scene_file gave with `scene` as its settings).
std::string scene_to_sdl(const SceneDescription& scene, const Scene& built, const ConvertOptions& options = {});
/// Same, building the Scene first (validate_scene: the mesh files are read then).
std::string scene_to_sdl(const SceneDescription& scene, const ConvertOptions& options = {});

/// The .ini that renders it deterministically and linearly: +W +H -D -A +FN16 File_Gamma=1.0
/// (or +FE). With image.samples = n > 1 the render is n·W × n·H, one sample per pixel on
/// exactly Whitted's n×n grid; averaging n×n blocks gives Whitted's box filter.
std::string ini_for(const SceneDescription& scene, const std::string& pov_file, const std::string& image_file,
                    const ConvertOptions& options = {});

/// An upper bound of any pixel value of the scene (ambient + all lights at full strength,
/// mirrors summed over max_depth, background): at most 1 means a PNG cannot clip it.
double radiance_upper_bound(const SceneDescription& scene);

/// Throws std::invalid_argument unless POV-Ray 3.7 can open the file `pov_path` names from the
/// .ini beside it: its name (the last part of the path) must be printable ASCII without `"` or
/// `\` (POV-Ray fails to open `café.pov`, and the .ini quotes the name). Called before any work.
void check_pov_file_name(const std::string& pov_path);

/// Writes `pov_path` and the .ini beside it (same name, .ini). Returns the .ini path.
/// Throws InputError for anything the description cannot express.
std::string write_pov_files(const SceneDescription& scene, const Scene& built, const std::string& pov_path,
                            const ConvertOptions& options = {});
/// Same, building the Scene first (validate_scene: the mesh files are read then).
std::string write_pov_files(const SceneDescription& scene, const std::string& pov_path,
                            const ConvertOptions& options = {});

}  // namespace whitted::pov
