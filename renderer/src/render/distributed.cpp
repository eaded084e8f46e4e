// SPDX-License-Identifier: MIT
#include "render/distributed.h"

#include "core/plugin.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace whitted {

std::string mpi_launch_evidence() {
    const auto value = [](const char* name) -> std::string {
        const char* v = std::getenv(name);
        return v ? v : "";
    };
    const std::string forced = value("WHITTED_MPI");
    if (forced == "0") return "";
    if (forced == "1") return "WHITTED_MPI=1";
    // Open MPI's mpirun; PMIx (Open MPI 4+, srun --mpi=pmix); PMI-1/2 (MPICH's hydra, srun --mpi=pmi2).
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (!value(name).empty()) return std::string(name) + "=" + value(name);
    // A task of an srun job step (SLURM_STEP_ID), not the batch script itself, which has
    // SLURM_PROCID and SLURM_NTASKS too but is one process.
    if (!value("SLURM_PROCID").empty() && !value("SLURM_STEP_ID").empty() && !value("SLURM_NTASKS").empty() &&
        value("SLURM_NTASKS") != "1")
        return "SLURM_NTASKS=" + value("SLURM_NTASKS") + " (srun)";
    return "";
}

std::unique_ptr<WorkExchange> open_mpi_exchange() {
    using Open = WorkExchange* (*)(std::string * error);
    const auto open = reinterpret_cast<Open>(plugin_symbol(
        "libwhitted_mpi.so", "whitted_mpi_open",
        "the MPI plug-in, needed to run under mpirun or srun; set WHITTED_MPI=0 to render in one process"));
    std::string error;
    WorkExchange* exchange = open(&error);
    if (!exchange) throw std::runtime_error(error);
    return std::unique_ptr<WorkExchange>(exchange);
}

namespace {

/// What a rank sends rank 0 for one tile: its ray counts, then its pixels row by row.
struct TileHeader {
    uint64_t camera, shadow, reflected;
};

}  // namespace

RenderedTiles render_distributed(const Scene& scene, const Accelerator& accelerator, const RenderJob& options,
                                 WorkExchange& exchange) {
    if (!options.layers.empty())
        throw std::invalid_argument(
            "render layers are not available in a distributed (MPI) render yet; render them in one process");
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    // The exchange hands out items 0..item_count−1: every tile, or the crop window's (ascending).
    const std::vector<size_t> cropped =
        options.crop ? render_tiles_overlapping(scene, *options.crop) : std::vector<size_t>{};
    const size_t item_count = options.crop ? cropped.size() : render_tile_count(scene.width, scene.height);
    const auto tile_of = [&](size_t item) { return options.crop ? cropped[item] : item; };
    const auto item_of = [&](size_t tile) {
        return options.crop ? size_t(std::lower_bound(cropped.begin(), cropped.end(), tile) - cropped.begin()) : tile;
    };
    const bool root = exchange.rank() == 0;

    // Rank 0 keeps the other ranks' tiles as they arrive (from the exchange's thread, while its
    // own render writes into its image) and copies them in afterwards.
    std::vector<std::vector<float>> received(root ? item_count : 0);
    std::atomic<uint64_t> remote_camera{0}, remote_shadow{0}, remote_reflected{0};
    std::atomic<bool> bad_payload{false};
    const auto receive = [&](size_t item, const void* payload, size_t bytes) {
        if (item >= item_count) {
            bad_payload = true;
            return;
        }
        const TileRect rect = render_tile_rect(scene.width, scene.height, tile_of(item));
        if (bytes != sizeof(TileHeader) + rect.pixels() * 3 * sizeof(float)) {
            bad_payload = true;
            return;
        }
        TileHeader header;
        std::memcpy(&header, payload, sizeof header);
        remote_camera += header.camera, remote_shadow += header.shadow, remote_reflected += header.reflected;
        std::vector<float>& pixels = received[item];
        pixels.resize(rect.pixels() * 3);
        std::memcpy(pixels.data(), static_cast<const char*>(payload) + sizeof header, pixels.size() * sizeof(float));
    };
    exchange.begin(item_count, receive, options.cancel);

    const auto remote_rays = [&] { return remote_camera.load() + remote_shadow.load() + remote_reflected.load(); };
    const auto report = [&](api::Progress progress) {
        progress.tiles_done = exchange.items_done();
        progress.tiles_total = item_count;
        progress.rays += remote_rays();
        progress.seconds = std::chrono::duration<double>(clock::now() - start).count();
        options.on_progress(progress);
    };

    RenderJob local = options;
    local.crop.reset();  // the items are the window's tiles already
    local.next_tile = [&](size_t& tile) {
        size_t item;
        if (!exchange.next_item(item)) return false;
        tile = tile_of(item);
        return true;
    };
    local.on_tile_done = [&](size_t tile, const Image& image, const RayCounts& counts) {
        if (root) {
            exchange.item_done(item_of(tile), nullptr, 0);
            return;
        }
        const TileRect rect = render_tile_rect(scene.width, scene.height, tile);
        thread_local std::vector<char> buffer;
        buffer.resize(sizeof(TileHeader) + rect.pixels() * 3 * sizeof(float));
        const TileHeader header{counts.camera, counts.shadow, counts.reflected};
        std::memcpy(buffer.data(), &header, sizeof header);
        char* out = buffer.data() + sizeof header;
        const size_t row_bytes = size_t(rect.x_end - rect.x_begin) * 3 * sizeof(float);
        for (int y = rect.y_begin; y < rect.y_end; ++y, out += row_bytes)
            std::memcpy(out, image.pixel(rect.x_begin, y), row_bytes);
        exchange.item_done(item_of(tile), buffer.data(), buffer.size());
    };
    local.on_progress = nullptr;
    if (root && options.on_progress) local.on_progress = report;

    RenderedTiles result = render(scene, accelerator, local);
    uint64_t local_rays = result.rays.total();
    const bool complete = exchange.end([&] {
        if (root && options.on_progress) report({0, 0, local_rays, 0});
    });
    if (bad_payload)
        throw std::runtime_error("a rank sent a tile of the wrong size (do all ranks read the same scene?)");

    if (root) {
        for (size_t item = 0; item < item_count; ++item) {
            const std::vector<float>& pixels = received[item];
            if (pixels.empty()) continue;  // rendered here, or (cancelled) never
            const TileRect rect = render_tile_rect(scene.width, scene.height, tile_of(item));
            const size_t row_floats = size_t(rect.x_end - rect.x_begin) * 3;
            for (int y = rect.y_begin; y < rect.y_end; ++y)
                std::memcpy(&result.image.rgb[3 * (size_t(y) * scene.width + rect.x_begin)],
                            &pixels[(y - rect.y_begin) * row_floats], row_floats * sizeof(float));
        }
        result.rays.camera += remote_camera, result.rays.shadow += remote_shadow,
            result.rays.reflected += remote_reflected;
    }
    result.cancelled = result.cancelled || !complete;
    result.seconds = std::chrono::duration<double>(clock::now() - start).count();
    if (root && options.on_progress) report({0, 0, local_rays, 0});
    return result;
}

}  // namespace whitted
