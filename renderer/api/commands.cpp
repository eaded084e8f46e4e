// SPDX-License-Identifier: MIT
// What the `whitted` program's render and convert need of the library beyond loading, rendering
// and writing (whitted/whitted.h): the usage checks they make before any work, the conversion
// by the output's extension, the MPI job and Embree's instruction set.

#include "api_internal.h"
#include "converters/pov_writer.h"
#include "converters/yaml_writer.h"
#include "output/atomic_files.h"
#include "output/image_output.h"
#include "render/accelerator_device.h"
#include "render/distributed.h"
#include "scene/description.h"
#include "scene/errors.h"
#include "scene/layer_names.h"
#include "scene/text_checks.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace whitted::api {

static_assert(limits::max_image_side == whitted::limits::max_image_side);
static_assert(limits::max_samples == whitted::limits::max_samples);
static_assert(limits::max_depth == whitted::limits::max_depth);
static_assert(limits::max_scene_file_bytes == whitted::limits::max_scene_file_bytes);

namespace {

/// A usage error when writing `target` would replace `input`, a file the same command reads.
void refuse_overwriting_input(const std::filesystem::path& target, const std::string& input) {
    std::error_code error;
    if (std::filesystem::exists(target, error) && std::filesystem::equivalent(target, input, error) && !error)
        throw std::invalid_argument("cannot write '" + target.string() + "': it is the input '" + input +
                                    "' of the same command");
}

/// What convert() writes for `output`: .pov and the .ini beside it, or YAML.
struct ConvertTarget {
    bool yaml = false;
    std::filesystem::path ini;
};

ConvertTarget convert_target(const std::string& output) {
    const std::string ext = std::filesystem::path(output).extension().string();
    ConvertTarget target;
    target.yaml = ext == ".yaml" || ext == ".yml";
    if (!target.yaml && ext != ".pov")
        throw std::invalid_argument("cannot convert to '" + output + "': unknown format '" + ext +
                                    "'; supported: .pov (POV-Ray 3.7), .yaml/.yml (Whitted's own format)");
    target.ini = output;
    target.ini.replace_extension(".ini");
    return target;
}

}  // namespace

Error error_of_current_exception(const std::string& doing) {
    return current_error({doing});
}

// ---- the MPI job ------------------------------------------------------------------------------

std::string mpi_launch_evidence() {
    return whitted::mpi_launch_evidence();
}

MpiJob::MpiJob(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
MpiJob::MpiJob(MpiJob&&) noexcept = default;
MpiJob& MpiJob::operator=(MpiJob&&) noexcept = default;
MpiJob::~MpiJob() = default;

int MpiJob::rank() const {
    return m_impl->exchange->rank();
}
int MpiJob::size() const {
    return m_impl->exchange->size();
}
std::string MpiJob::thread_support() const {
    return m_impl->exchange->thread_support();
}
void MpiJob::finalize() {
    m_impl->exchange->finalize();
}
const MpiJob::Impl& impl_of(const MpiJob& job) {
    return *job.m_impl;
}

Expected<MpiJob> join_mpi_job() {
    return guarded<MpiJob>("starting MPI", [&]() -> Expected<MpiJob> {
        auto impl = std::make_unique<MpiJob::Impl>();
        impl->exchange = open_mpi_exchange();
        return MpiJob(std::move(impl));
    });
}

// ---- render's usage checks ------------------------------------------------------------------

Expected<void> check_image_output(const std::string& path, const WriteOptions& options,
                                  const std::vector<std::string>& layers, const std::string& layers_from,
                                  const std::string& input) {
    return guarded<void>({"checking " + input, input, Error::Kind::bad_input}, [&]() -> Expected<void> {
        check_output_path(path);
        OutputOptions output = output_options(options);
        if (!parse_layers(layers).empty()) output.layers_from = layers_from;
        check_output_options(path, output);
        // `whitted render s.png -o s.png` must not overwrite the scene: the same file by any
        // name, a link included.
        std::error_code error;
        if (!input.empty() && std::filesystem::equivalent(path, input, error))
            throw std::invalid_argument("refusing to write the image to '" + path + "': it is the scene file '" +
                                        input + "'");
        refuse_symlink_target(path);
        return {};
    });
}

std::string layer_choices() {
    return whitted::layer_choices();
}

Expected<EmbreeInfo> embree_info() {
    return guarded<EmbreeInfo>("asking Embree", [&]() -> Expected<EmbreeInfo> {
        const std::string isa = embree_isa_from_environment();
        const whitted::EmbreeInfo info = whitted::embree_info(isa);
        return EmbreeInfo{info.version, info.isas, info.isa_in_use, !isa.empty(), info.lane_width};
    });
}

Expected<void> check_embree_isa() {
    return guarded<void>({"checking WHITTED_EMBREE_ISA", "", Error::Kind::bad_input}, [&]() -> Expected<void> {
        require_embree_isa(embree_isa_from_environment());
        return {};
    });
}

void use_huge_pages(bool on) {
    whitted::use_huge_pages(on);
}

std::string printable(const std::string& text, size_t max_characters) {
    return whitted::printable(text, max_characters);
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
    return whitted::did_you_mean(word, candidates);
}

// ---- convert --------------------------------------------------------------------------------

Expected<void> check_convert_output(const std::string& output, const std::string& input) {
    return guarded<void>("converting " + input, [&]() -> Expected<void> {
        const ConvertTarget target = convert_target(output);
        if (!input.empty()) refuse_overwriting_input(output, input);
        check_can_write(output);
        if (!target.yaml) {
            pov::check_pov_file_name(output);
            if (!input.empty()) refuse_overwriting_input(target.ini, input);
            check_can_write(target.ini);
        }
        refuse_symlink_target(output);
        if (!target.yaml) refuse_symlink_target(target.ini);
        return {};
    });
}

Expected<std::vector<std::string>> convert(const Scene& scene, const std::string& output) {
    using Written = std::vector<std::string>;
    return guarded<Written>("converting " + scene.path(), [&]() -> Expected<Written> {
        const ConvertTarget target = convert_target(output);
        const Scene::Impl& loaded = impl_of(scene);
        const SceneDescription& description = loaded.converter_description();
        // An output that is a mesh or MTL file of the scene under another name (`mtllib
        // out.ini`, a mesh named `mesh.pov`): refused before a byte is written.
        for (const std::filesystem::path& file : {std::filesystem::path(output), target.ini}) {
            if (target.yaml && file == target.ini) continue;
            if (const std::string input = scene.input_file_at(file.string()); !input.empty())
                throw std::invalid_argument("cannot write '" + file.string() + "': it is " + input +
                                            ", an input of the same command");
        }
        if (target.yaml) {
            // Any scene Whitted reads (a course .xml file, say) in Whitted's own format.
            yaml::write_yaml_file(description, output);
            return Written{output};
        }
        const std::string ini = pov::write_pov_files(description, loaded.scene, output);
        return Written{output, ini};
    });
}

}  // namespace whitted::api
