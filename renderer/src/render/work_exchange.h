// SPDX-License-Identifier: MIT
#pragma once

// The interface between the program and its MPI plug-in (lib/libwhitted_mpi.so): standard
// library types only, so that the plug-in needs nothing else of Whitted.

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

namespace whitted {

/// A work queue shared by all ranks, with results sent back to rank 0: what the MPI plug-in
/// implements. Items are numbered 0..count−1 (tiles, or scenes for a sweep); each finished item
/// carries a byte payload. All methods but begin/end may be called from several threads at once.
class WorkExchange {
public:
    virtual ~WorkExchange() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    /// The thread support MPI_Init_thread gave (e.g. "MPI_THREAD_MULTIPLE"), for --stats.
    virtual std::string thread_support() const = 0;

    /// Starts a queue of `count` items. On rank 0, `receive(item, payload, bytes)` is called
    /// from the exchange's own thread for each item another rank finished. `cancel` (may be
    /// null) stops next_item and end early.
    virtual void begin(size_t count, std::function<void(size_t, const void*, size_t)> receive,
                       const std::atomic<bool>* cancel) = 0;
    /// The next item for this rank; false when the queue is empty (or cancelled).
    virtual bool next_item(size_t& item) = 0;
    /// `item` is finished here; on ranks other than 0 its payload is sent to rank 0 (copied
    /// before the call returns). On rank 0 the payload is ignored (the caller keeps it).
    virtual void item_done(size_t item, const void* payload, size_t bytes) = 0;
    /// Items finished on all ranks as far as rank 0 knows (on other ranks: this rank's).
    virtual size_t items_done() const = 0;
    /// Waits until every item is finished and received (rank 0) or this rank's are sent; calls
    /// `tick` every 200 ms meanwhile. False if cancelled first.
    virtual bool end(const std::function<void()>& tick) = 0;
    /// MPI_Finalize. Call once, after the last end(), on the thread that opened the exchange.
    virtual void finalize() = 0;
};

}  // namespace whitted
