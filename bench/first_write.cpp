// SPDX-License-Identifier: MIT
// What the first write of fresh memory costs a process, and whether a second thread shares it
// (docs/performance.md, "Start-up"; bench/log.md). Build and run:
//
//   c++ -O2 -pthread bench/first_write.cpp -o first_write && ./first_write 3 && ./first_write 48
//
// For a block of MB megabytes from mmap it prints the time of: MADV_POPULATE_WRITE (as the
// program's operator new does for blocks of 1 MiB or more, renderer/app/large_blocks.cpp), the
// first memset of the block (one thread, then two halves on two threads, each on a fresh block),
// a second memset of memory already written, and the first memset of a fresh block on 2 MiB
// boundaries that asked for transparent huge pages (as operator new gives a block of 2 MiB or
// more where huge pages pay); with the system's huge pages `never` that last is 4 KiB pages.
#include <sys/mman.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

char* fresh_block(size_t bytes, double& populate_ms) {
    void* block = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (block == MAP_FAILED) {
        std::perror("mmap");
        std::exit(1);
    }
    const auto start = std::chrono::steady_clock::now();
    madvise(block, bytes, 23);  // MADV_POPULATE_WRITE (Linux 5.14)
    populate_ms = milliseconds_since(start);
    return static_cast<char*>(block);
}

}  // namespace

int main(int argc, char** argv) {
    const double megabytes = argc > 1 ? std::atof(argv[1]) : 3.0;
    const auto bytes = size_t(megabytes * 1048576.0);
    double populate_one = 0, populate_two = 0;
    char* one = fresh_block(bytes, populate_one);
    auto start = std::chrono::steady_clock::now();
    std::memset(one, 0, bytes);
    const double first_one = milliseconds_since(start);
    start = std::chrono::steady_clock::now();
    std::memset(one, 1, bytes);
    const double second = milliseconds_since(start);
    char* two = fresh_block(bytes, populate_two);
    start = std::chrono::steady_clock::now();
    std::thread other([&] { std::memset(two, 0, bytes / 2); });
    std::memset(two + bytes / 2, 0, bytes - bytes / 2);
    other.join();
    const double first_two = milliseconds_since(start);
    const size_t huge = size_t(2) << 20, rounded = (bytes + huge - 1) / huge * huge;
    void* mapping = mmap(nullptr, rounded + huge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapping == MAP_FAILED) {
        std::perror("mmap");
        return 1;
    }
    char* three = reinterpret_cast<char*>((reinterpret_cast<uintptr_t>(mapping) + huge - 1) / huge * huge);
    madvise(three, rounded, MADV_HUGEPAGE);
    start = std::chrono::steady_clock::now();
    std::memset(three, 0, bytes);
    const double first_huge = milliseconds_since(start);
    std::printf(
        "%.1f MB: populate %.2f ms; first write, one thread %.2f ms, two threads %.2f ms "
        "(populate %.2f ms); second write %.2f ms; first write in huge pages %.2f ms\n",
        megabytes, populate_one, first_one, first_two, populate_two, second, first_huge);
    return 0;
}
