// SPDX-License-Identifier: MIT
#pragma once

// The library's private side of whitted::api::Scene: the parsed description (the converters read
// it) and the validated render Scene, with the BVH built once on demand; and of api::MpiJob. Only
// the library (and `whitted live`, which renders a description it edits) include this; the
// public headers never do.

#include "output/image_output.h"
#include "render/accelerator.h"
#include "render/work_exchange.h"
#include "scene/description.h"
#include "scene/errors.h"
#include "scene/scene.h"
#include "scene/text_checks.h"
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
    double read_seconds = 0;         ///< load_scene_*: reading, validating and loading meshes, wall time
    std::vector<NotedInput> inputs;  ///< the files read to load it (Scene::input_file_at)

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

/// Runs `work`, turning what it throws into an Error by the one mapping (scene/errors.h).
template <class T, class Work>
Expected<T> guarded(const ErrorContext& context, Work&& work) {
    try {
        return work();
    } catch (...) {
        return current_error(context);
    }
}
/// The same where the work is on input already accepted; `doing` finishes "out of memory while ...".
template <class T, class Work>
Expected<T> guarded(const std::string& doing, Work&& work) {
    return guarded<T>(ErrorContext(doing), std::forward<Work>(work));
}

struct MpiJob::Impl {
    std::unique_ptr<WorkExchange> exchange;
};

const MpiJob::Impl& impl_of(const MpiJob& job);

}  // namespace whitted::api
