// SPDX-License-Identifier: MIT
#pragma once

// The library's private side of whitted::api::Scene: the parsed description (the converters read
// it) and the validated render Scene, with the BVH built once on demand. Only the library (and the
// `whitted` program's `live`, which renders a description it edits, and `render` under MPI)
// include this; the public headers never do.

#include "output/image_output.h"
#include "render/accelerator.h"
#include "render/work_exchange.h"
#include "scene/description.h"
#include "scene/scene.h"
#include "whitted/whitted.h"

#include <memory>
#include <mutex>

namespace whitted::api {

struct Scene::Impl {
    /// What the file said when it was loaded; without its objects when `objects_kept` is false
    /// (SceneUse::render_only: read in one pass, each object's description let go once validated).
    SceneDescription description;
    bool objects_kept = true;
    whitted::Scene scene;
    double read_seconds = 0;  ///< load_scene_*: reading, validating and loading meshes, wall time

    /// The whole description, for the converters; throws std::invalid_argument without its objects.
    const SceneDescription& converter_description() const;

    /// The BVH, built by the first caller with `threads` build threads (0 = all cores) and kept.
    /// Embree's instruction set comes from $WHITTED_EMBREE_ISA, as for `whitted render`.
    const Accelerator& accelerator(int threads) const;

private:
    mutable std::mutex m_mutex;
    mutable std::unique_ptr<Accelerator> m_accelerator;
};

/// The writers' options from the public ones, for write_image and `whitted render`'s usage checks
/// (which add where render layers were asked for).
OutputOptions output_options(const WriteOptions& options);

/// The private side of a Scene, for the library's own functions.
const Scene::Impl& impl_of(const Scene& scene);

/// api::render with the tiles shared among MPI ranks through `exchange` (null: one process), for
/// `whitted render` under mpirun (docs/distributed.md); not in the public API yet. On a rank other
/// than 0 the image holds only the tiles that rank rendered.
Expected<RenderResult> render_distributed(const Scene& scene, const RenderOptions& options, WorkExchange* exchange);

}  // namespace whitted::api
