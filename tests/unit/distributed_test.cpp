// SPDX-License-Identifier: MIT
// whitted::render's tile source and sink (RenderJob::next_tile, on_tile_done), and
// render_distributed over an in-process WorkExchange whose "ranks" are threads of this process:
// the packing, sending and assembly of tiles give the one-process image bit for bit. The same
// over MPI, with real ranks: tests/mpi (label mpi).

#include "render/distributed.h"
#include "render/accelerator.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>

namespace whitted {
namespace {

// 70×45 with 32-pixel tiles: 3×2 tiles, the last column 6 wide and the last row 13 high.
std::string scene_text(int samples) {
    return test::join_lines({
        "camera: {eye: [0.3, 1.5, 6], look_at: [0, 0.2, 0], fov: 55}",
        "image: {width: 70, height: 45, background: [0.1, 0.2, 0.3], samples: " + std::to_string(samples) + "}",
        "render: {max_depth: 4}",
        "lights:",
        "  - {type: point, position: [-4, 5, 3], intensity: [1, 0.9, 0.8]}",
        "materials:",
        "  shiny: {ka: 0.05, kd: [0.6, 0.3, 0.2], ks: 0.5, p: 40, km: 0.3}",
        "  floor: {ka: 0.05, kd: 0.5, km: 0.5}",
        "objects:",
        "  - {type: sphere, center: [-1, 0.2, 0], radius: 1, material: shiny}",
        "  - {type: box, min: [0.5, -1, -1], max: [2, 0.5, 0.5], material: shiny}",
        "  - {type: plane, point: [0, -1, 0], normal: [0, 1, 0], material: floor}",
    });
}

bool same_pixels(const Image& a, const Image& b) {
    return a.rgb.size() == b.rgb.size() && std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

TEST(RenderTiles, CountAndRectanglesCoverTheImageRowByRow) {
    EXPECT_EQ(render_tile_count(70, 45), 6u);
    EXPECT_EQ(render_tile_count(64, 32), 2u);
    EXPECT_EQ(render_tile_count(1, 1), 1u);
    const TileRect last = render_tile_rect(70, 45, 5);
    EXPECT_EQ(last.x_begin, 64);
    EXPECT_EQ(last.x_end, 70);
    EXPECT_EQ(last.y_begin, 32);
    EXPECT_EQ(last.y_end, 45);
    EXPECT_EQ(last.pixels(), 6u * 13u);
    const TileRect second = render_tile_rect(70, 45, 1);
    EXPECT_EQ(second.x_begin, 32);
    EXPECT_EQ(second.x_end, 64);
    EXPECT_EQ(second.y_begin, 0);
    EXPECT_EQ(second.y_end, 32);
    size_t pixels = 0;
    for (size_t t = 0; t < 6; ++t) pixels += render_tile_rect(70, 45, t).pixels();
    EXPECT_EQ(pixels, 70u * 45u);
}

// Tiles handed out last to first, on two threads: the same image, and every tile reported done
// exactly once.
TEST(RenderTiles, ATileSourceInAnyOrderGivesTheSameImage) {
    for (const int samples : {1, 2}) {
        const Scene scene = test::scene_from(scene_text(samples));
        const Accelerator accelerator(scene, 2);
        RenderJob options;
        options.threads = 2;
        const RenderedTiles whole = render(scene, accelerator, options);
        ASSERT_FALSE(whole.cancelled);
        ASSERT_GT(std::set<float>(whole.image.rgb.begin(), whole.image.rgb.end()).size(), 100u);

        std::mutex mutex;
        size_t left = render_tile_count(scene.width, scene.height);
        std::multiset<size_t> done;
        options.next_tile = [&](size_t& tile) {
            std::lock_guard lock(mutex);
            if (left == 0) return false;
            tile = --left;
            return true;
        };
        options.on_tile_done = [&](size_t tile, const Image&, const RayCounts& counts) {
            std::lock_guard lock(mutex);
            done.insert(tile);
            EXPECT_EQ(counts.camera, render_tile_rect(scene.width, scene.height, tile).pixels() * samples * samples);
        };
        const RenderedTiles reversed = render(scene, accelerator, options);
        EXPECT_FALSE(reversed.cancelled);
        EXPECT_TRUE(same_pixels(reversed.image, whole.image)) << samples << " sample(s)";
        EXPECT_EQ(reversed.rays.total(), whole.rays.total());
        EXPECT_EQ(done, (std::multiset<size_t>{0, 1, 2, 3, 4, 5}));
    }
}

// A source that gives only the even tiles: those are the whole render's, the others untouched
// (zero), and the render is not "cancelled" (this process was given only part of the image).
TEST(RenderTiles, OnlyTheTilesGivenAreRendered) {
    const Scene scene = test::scene_from(scene_text(1));
    const Accelerator accelerator(scene, 1);
    RenderJob options;
    options.threads = 2;
    const RenderedTiles whole = render(scene, accelerator, options);
    std::mutex mutex;
    size_t next = 0;
    options.next_tile = [&](size_t& tile) {
        std::lock_guard lock(mutex);
        if (next >= 6) return false;
        tile = next;
        next += 2;
        return true;
    };
    const RenderedTiles part = render(scene, accelerator, options);
    EXPECT_FALSE(part.cancelled);
    for (size_t t = 0; t < 6; ++t) {
        const TileRect rect = render_tile_rect(scene.width, scene.height, t);
        for (int y = rect.y_begin; y < rect.y_end; ++y)
            for (int x = rect.x_begin; x < rect.x_end; ++x)
                for (int c = 0; c < 3; ++c) {
                    const float expected = t % 2 == 0 ? whole.image.pixel(x, y)[c] : 0.0f;
                    ASSERT_EQ(part.image.pixel(x, y)[c], expected) << "tile " << t << " pixel " << x << "," << y;
                }
    }
}

/// A WorkExchange for two "ranks" in one process: rank 0 holds the queue; rank 1's finished
/// items are handed to rank 0's receive callback as bytes, as MPI would deliver them.
struct SharedQueue {
    std::mutex mutex;
    size_t count = 0, next = 0, done = 0;
    std::function<void(size_t, const void*, size_t)> receive;
};

class InProcessExchange final : public WorkExchange {
public:
    InProcessExchange(SharedQueue& queue, int rank) : m_queue(queue), m_rank(rank) {}
    int rank() const override { return m_rank; }
    int size() const override { return 2; }
    std::string thread_support() const override { return "in-process"; }
    void begin(size_t count, std::function<void(size_t, const void*, size_t)> receive,
               const std::atomic<bool>*) override {
        std::lock_guard lock(m_queue.mutex);
        if (m_rank == 0) m_queue.receive = std::move(receive), m_queue.count = count;
    }
    bool next_item(size_t& item) override {
        std::unique_lock lock(m_queue.mutex);
        while (!m_queue.receive) {  // rank 1 waits until rank 0 has begun
            lock.unlock();
            std::this_thread::yield();
            lock.lock();
        }
        if (m_queue.next >= m_queue.count) return false;
        item = m_queue.next++;
        return true;
    }
    void item_done(size_t item, const void* payload, size_t bytes) override {
        std::lock_guard lock(m_queue.mutex);
        if (m_rank != 0) m_queue.receive(item, payload, bytes);
        ++m_queue.done;
        ++m_mine;
    }
    size_t items_done() const override { return m_queue.done; }
    bool end(const std::function<void()>&) override {
        for (;;) {
            {
                std::lock_guard lock(m_queue.mutex);
                if (m_rank != 0 || m_queue.done == m_queue.count) return true;
            }
            std::this_thread::yield();
        }
    }
    void finalize() override {}
    size_t mine() const { return m_mine; }

private:
    SharedQueue& m_queue;
    const int m_rank;
    size_t m_mine = 0;
};

TEST(RenderDistributed, TwoRanksInOneProcessGiveTheOneProcessImage) {
    for (const int samples : {1, 3}) {
        const Scene scene = test::scene_from(scene_text(samples));
        const Accelerator accelerator(scene, 2);
        RenderJob options;
        options.threads = 1;
        const RenderedTiles whole = render(scene, accelerator, options);

        SharedQueue queue;
        InProcessExchange rank0(queue, 0), rank1(queue, 1);
        RenderedTiles root, other;
        std::thread second([&] { other = render_distributed(scene, accelerator, options, rank1); });
        root = render_distributed(scene, accelerator, options, rank0);
        second.join();
        EXPECT_FALSE(root.cancelled);
        EXPECT_TRUE(same_pixels(root.image, whole.image)) << samples << " sample(s)";
        EXPECT_EQ(root.rays.total(), whole.rays.total()) << "rank 0 counts the rays of both ranks";
        EXPECT_EQ(rank0.mine() + rank1.mine(), 6u);
    }
}

TEST(RenderDistributed, RenderLayersAreRefused) {
    const Scene scene = test::scene_from(scene_text(1));
    const Accelerator accelerator(scene, 1);
    RenderJob options;
    options.layers = parse_layers({"diffuse"});
    SharedQueue queue;
    InProcessExchange rank0(queue, 0);
    EXPECT_THROW(render_distributed(scene, accelerator, options, rank0), std::invalid_argument);
}

TEST(MpiLaunchEvidence, ReadsTheLaunchersVariables) {
    for (const char* name : {"WHITTED_MPI", "OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "SLURM_PROCID",
                             "SLURM_STEP_ID", "SLURM_NTASKS"})
        unsetenv(name);
    EXPECT_EQ(mpi_launch_evidence(), "");
    setenv("SLURM_PROCID", "0", 1);
    setenv("SLURM_NTASKS", "4", 1);
    EXPECT_EQ(mpi_launch_evidence(), "") << "a batch script (no job step) is one process";
    setenv("SLURM_STEP_ID", "0", 1);
    EXPECT_EQ(mpi_launch_evidence(), "SLURM_NTASKS=4 (srun)");
    setenv("OMPI_COMM_WORLD_SIZE", "3", 1);
    EXPECT_EQ(mpi_launch_evidence(), "OMPI_COMM_WORLD_SIZE=3");
    setenv("WHITTED_MPI", "0", 1);
    EXPECT_EQ(mpi_launch_evidence(), "") << "WHITTED_MPI=0 wins";
    setenv("WHITTED_MPI", "1", 1);
    EXPECT_EQ(mpi_launch_evidence(), "WHITTED_MPI=1");
    for (const char* name : {"WHITTED_MPI", "OMPI_COMM_WORLD_SIZE", "SLURM_PROCID", "SLURM_STEP_ID", "SLURM_NTASKS"})
        unsetenv(name);
    setenv("PMIX_RANK", "2", 1);
    EXPECT_EQ(mpi_launch_evidence(), "PMIX_RANK=2");
    unsetenv("PMIX_RANK");
}

}  // namespace
}  // namespace whitted
