// SPDX-License-Identifier: MIT
#pragma once

// One image rendered by several processes (MPI ranks), docs/distributed.md. Every rank loads the
// scene and builds its own BVH; rank 0 hands out tiles from a queue, every rank (rank 0 too)
// renders what it is given, and the finished tiles go to rank 0, which alone writes the file.
// Pixels depend only on the scene, so the image is the single-process image bit for bit.
//
// The message passing lives in a plug-in, lib/libwhitted_mpi.so, loaded only when the
// environment says this process is an MPI rank: the program itself never links libmpi, so a
// render without MPI starts as fast as before.

#include "render/renderer.h"
#include "render/work_exchange.h"

#include <memory>
#include <string>

namespace whitted {

/// Why this process looks like one rank of an MPI job (e.g. "OMPI_COMM_WORLD_SIZE=4"), or ""
/// when it does not. WHITTED_MPI=0 says never, WHITTED_MPI=1 always.
std::string mpi_launch_evidence();

/// Loads lib/libwhitted_mpi.so and initialises MPI. Throws std::runtime_error (saying where
/// the plug-in was looked for) when it cannot.
std::unique_ptr<WorkExchange> open_mpi_exchange();

/// render() with the tiles handed out by `exchange`: on rank 0 the result holds the whole
/// image (and the rays of all ranks); on the others only the tiles they rendered. Render
/// layers are refused (std::invalid_argument): they are not sent between ranks yet.
RenderedTiles render_distributed(const Scene& scene, const Accelerator& accelerator, const RenderJob& options,
                                 WorkExchange& exchange);

}  // namespace whitted
