// SPDX-License-Identifier: MIT
// lib/libwhitted_mpi.so: the WorkExchange of render/work_exchange.h over MPI. The only
// code that links libmpi; `whitted` loads it when it finds itself started by mpirun or srun.
//
// Rank 0 holds the queue: a counter over items 0..count−1. Its own worker threads take one item
// at a time from the counter; the other ranks ask for batches over MPI, sized by guided
// self-scheduling (a quarter of what is left divided among the ranks, 1..256), so the batches
// are large while much is left and single items at the end, where tiles that cost more (mirrors)
// would otherwise leave ranks idle. A rank asks for its next batch while it still has work
// (fewer than two items per core left), so the request's latency is hidden.
//
// On every rank one service thread does all the MPI calls (the worker threads only touch
// queues under a mutex), so MPI_THREAD_SERIALIZED is enough.

#include "render/work_exchange.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace whitted;
using namespace std::chrono_literals;

enum Tag : int { tag_request = 1, tag_grant = 2, tag_result = 3 };

std::string thread_level_name(int level) {
    switch (level) {
        case MPI_THREAD_SINGLE:
            return "MPI_THREAD_SINGLE";
        case MPI_THREAD_FUNNELED:
            return "MPI_THREAD_FUNNELED";
        case MPI_THREAD_SERIALIZED:
            return "MPI_THREAD_SERIALIZED";
        case MPI_THREAD_MULTIPLE:
            return "MPI_THREAD_MULTIPLE";
        default:
            return "level " + std::to_string(level);
    }
}

class MpiExchange final : public WorkExchange {
public:
    MpiExchange(int rank, int size, int provided) : m_rank(rank), m_size(size), m_provided(provided) {}
    ~MpiExchange() override {
        if (m_service.joinable()) m_service.join();
    }

    int rank() const override { return m_rank; }
    int size() const override { return m_size; }
    std::string thread_support() const override { return thread_level_name(m_provided); }

    void begin(size_t count, std::function<void(size_t, const void*, size_t)> receive,
               const std::atomic<bool>* cancel) override {
        if (m_service.joinable()) m_service.join();
        m_count = count;
        m_receive = std::move(receive);
        m_cancel = cancel;
        m_next = 0;
        m_done = 0;
        m_ranges.clear();
        m_outbound.clear();
        m_no_more = false;
        m_handed = m_sent = 0;
        m_finished = false;
        m_service = std::thread([this] {
            if (m_rank == 0)
                serve_queue();
            else
                serve_worker();
            std::lock_guard lock(m_mutex);
            m_finished = true;
            m_wake.notify_all();
        });
    }

    bool next_item(size_t& item) override {
        if (m_rank == 0) {
            size_t end;
            if (cancelled() || !take(1, item, end)) return false;
            return true;
        }
        std::unique_lock lock(m_mutex);
        for (;;) {
            if (cancelled()) return false;
            if (!m_ranges.empty()) {
                auto& front = m_ranges.front();
                item = front.first++;
                if (front.first == front.second) m_ranges.pop_front();
                ++m_handed;
                m_wake_service.notify_one();  // the stock shrank: maybe time to ask for more
                return true;
            }
            if (m_no_more) return false;
            m_wake.wait_for(lock, 10ms);
        }
    }

    void item_done(size_t item, const void* payload, size_t bytes) override {
        if (m_rank == 0) {
            ++m_done;
            return;
        }
        std::vector<char> message(sizeof(uint64_t) + bytes);
        const uint64_t index = item;
        std::memcpy(message.data(), &index, sizeof index);
        if (bytes) std::memcpy(message.data() + sizeof index, payload, bytes);
        std::lock_guard lock(m_mutex);
        m_outbound.push_back(std::move(message));
        m_wake_service.notify_one();
    }

    size_t items_done() const override { return m_rank == 0 ? m_done.load() : m_sent.load(); }

    bool end(const std::function<void()>& tick) override {
        {
            std::unique_lock lock(m_mutex);
            while (!m_wake.wait_for(lock, 200ms, [this] { return m_finished; })) {
                lock.unlock();
                if (tick) tick();
                lock.lock();
            }
        }
        m_service.join();
        if (cancelled()) return false;
        return m_rank == 0 ? m_done.load() == m_count : true;
    }

    void finalize() override {
        if (m_service.joinable()) m_service.join();
        MPI_Finalize();
    }

private:
    bool cancelled() const { return m_cancel && m_cancel->load(std::memory_order_relaxed); }

    /// Rank 0: up to `want` items [begin, end) from the counter; false when none are left.
    bool take(size_t want, size_t& begin, size_t& end) {
        size_t next = m_next.load();
        do {
            if (next >= m_count) return false;
            begin = next;
            end = std::min(m_count, next + want);
        } while (!m_next.compare_exchange_weak(next, end));
        return true;
    }

    void serve_queue() {
        int workers_told_done = 0;
        std::vector<char> buffer;
        while (!cancelled()) {
            if (m_done.load() == m_count && workers_told_done == m_size - 1) return;
            int flag = 0;
            MPI_Status status;
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
            if (!flag) {
                std::this_thread::sleep_for(100us);
                continue;
            }
            if (status.MPI_TAG == tag_request) {
                MPI_Recv(nullptr, 0, MPI_BYTE, status.MPI_SOURCE, tag_request, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                const size_t left = m_count - std::min(m_count, m_next.load());
                const size_t want = std::clamp<size_t>(left / (4 * size_t(m_size)), 1, 256);
                uint64_t grant[2] = {0, 0};
                size_t begin, end;
                if (take(want, begin, end))
                    grant[0] = begin, grant[1] = end;
                else
                    ++workers_told_done;  // an empty grant: this rank asks no more
                MPI_Send(grant, 2, MPI_UINT64_T, status.MPI_SOURCE, tag_grant, MPI_COMM_WORLD);
            } else if (status.MPI_TAG == tag_result) {
                int bytes = 0;
                MPI_Get_count(&status, MPI_BYTE, &bytes);
                buffer.resize(size_t(bytes));
                MPI_Recv(buffer.data(), bytes, MPI_BYTE, status.MPI_SOURCE, tag_result, MPI_COMM_WORLD,
                         MPI_STATUS_IGNORE);
                uint64_t index = 0;
                if (size_t(bytes) >= sizeof index) {
                    std::memcpy(&index, buffer.data(), sizeof index);
                    m_receive(size_t(index), buffer.data() + sizeof index, size_t(bytes) - sizeof index);
                }
                ++m_done;
            } else {
                // Nothing else is ever sent; take it off the queue so that it cannot block us.
                MPI_Recv(nullptr, 0, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            }
        }
    }

    void serve_worker() {
        const size_t low_water = 2 * std::max(1u, std::thread::hardware_concurrency());
        bool asked = false;
        MPI_Request request = MPI_REQUEST_NULL;
        uint64_t grant[2] = {0, 0};
        std::vector<std::vector<char>> sending;
        while (!cancelled()) {
            bool ask = false;
            {
                std::lock_guard lock(m_mutex);
                size_t stock = 0;
                for (const auto& range : m_ranges) stock += range.second - range.first;
                ask = !m_no_more && !asked && stock < low_water;
            }
            if (ask) {
                MPI_Send(nullptr, 0, MPI_BYTE, 0, tag_request, MPI_COMM_WORLD);
                MPI_Irecv(grant, 2, MPI_UINT64_T, 0, tag_grant, MPI_COMM_WORLD, &request);
                asked = true;
            }
            if (asked) {
                int flag = 0;
                MPI_Test(&request, &flag, MPI_STATUS_IGNORE);
                if (flag) {
                    asked = false;
                    std::lock_guard lock(m_mutex);
                    if (grant[0] >= grant[1])
                        m_no_more = true;
                    else
                        m_ranges.emplace_back(size_t(grant[0]), size_t(grant[1]));
                    m_wake.notify_all();
                }
            }
            {
                std::lock_guard lock(m_mutex);
                sending.swap(m_outbound);
            }
            for (const std::vector<char>& message : sending) {
                MPI_Send(message.data(), int(message.size()), MPI_BYTE, 0, tag_result, MPI_COMM_WORLD);
                ++m_sent;
            }
            sending.clear();
            std::unique_lock lock(m_mutex);
            if (m_no_more && m_ranges.empty() && m_outbound.empty() && m_sent.load() == m_handed) return;
            if (m_outbound.empty()) m_wake_service.wait_for(lock, asked ? 200us : 2ms);
        }
        if (asked) {
            MPI_Cancel(&request);
            MPI_Request_free(&request);
        }
    }

    const int m_rank, m_size, m_provided;
    size_t m_count = 0;
    std::function<void(size_t, const void*, size_t)> m_receive;
    const std::atomic<bool>* m_cancel = nullptr;
    std::atomic<size_t> m_next{0};  // rank 0: the queue
    std::atomic<size_t> m_done{0};  // rank 0: items finished on all ranks

    std::mutex m_mutex;
    std::condition_variable m_wake;                  // worker threads and end(): items arrived, or the service ended
    std::condition_variable m_wake_service;          // the service thread: results to send, stock shrank
    std::deque<std::pair<size_t, size_t>> m_ranges;  // other ranks: granted, not yet handed out
    std::vector<std::vector<char>> m_outbound;       // other ranks: results not yet sent
    bool m_no_more = false, m_finished = false;
    size_t m_handed = 0;
    std::atomic<size_t> m_sent{0};
    std::thread m_service;
};

}  // namespace

/// Initialises MPI (once per process) and returns the exchange, or null with `error` set.
extern "C" __attribute__((visibility("default"))) WorkExchange* whitted_mpi_open(std::string* error) {
    int provided = MPI_THREAD_SINGLE;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
        *error = "MPI_Init_thread failed";
        return nullptr;
    }
    if (provided < MPI_THREAD_SERIALIZED) {
        *error = "this MPI gives only " + thread_level_name(provided) +
                 "; Whitted's service thread needs MPI_THREAD_SERIALIZED";
        MPI_Abort(MPI_COMM_WORLD, 1);
        return nullptr;
    }
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    // srun without a PMI plug-in starts N processes that each see a world of one: each would
    // render the whole image and write the file. Refuse instead.
    const char* ntasks = std::getenv("SLURM_NTASKS");
    const char* step = std::getenv("SLURM_STEP_ID");
    if (size == 1 && ntasks && step && std::atoi(ntasks) > 1 && !std::getenv("OMPI_COMM_WORLD_SIZE")) {
        *error = std::string("srun started ") + ntasks +
                 " tasks but MPI sees one: run srun --mpi=pmix (or pmi2), see docs/distributed.md";
        return nullptr;
    }
    return new MpiExchange(rank, size, provided);
}
