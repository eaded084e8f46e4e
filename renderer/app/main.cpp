// SPDX-License-Identifier: MIT
// The `whitted` program: render, convert and check scene files. A user of the public API
// (whitted/whitted.h) for every command; each turns the API's errors into messages and exit codes
// (0 ok, 1 failure while rendering or checking, 2 bad input or usage, 130/143 interrupted) through
// report.h.

#include "explain_command.h"
#include "large_blocks.h"
#include "live_command.h"
#include "report.h"
#include "whitted/whitted.h"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <sys/ioctl.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

namespace {

using namespace whitted;

using api::exit_bad_input, api::exit_failure, api::exit_ok;

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};
/// Until the render starts nothing is written and nothing checks g_cancel (parsing, loading
/// meshes, building the BVH can take seconds), so a signal then ends the program at once.
std::atomic<bool> g_exit_on_signal{true};
/// Under mpirun or srun: this process is one rank of a distributed render (docs/distributed.md).
std::optional<api::MpiJob> g_mpi_job;
/// CLOCK_MONOTONIC (ns) of the CancelWatchdog's latest 20 ms poll, 0 while no render runs: a
/// SIGCONT arriving long after it means this process had been stopped (see on_continue).
std::atomic<int64_t> g_watchdog_tick_ns{0};
/// CLOCK_MONOTONIC (ns) at which the watchdog last found its own poll more than 100 ms late: after
/// a stop the SIGCONT can reach a thread only after the watchdog woke and polled again.
std::atomic<int64_t> g_watchdog_stall_ns{0};

int64_t monotonic_ns() {
    timespec now{};
    ::clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe, unlike std::chrono's clocks
    return int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

extern "C" void on_signal(int signal) {
    if (g_exit_on_signal.load()) {
        static const char message[] = "whitted: interrupted; nothing written\n";
        [[maybe_unused]] const auto ignored = ::write(STDERR_FILENO, message, sizeof message - 1);
        ::_exit(128 + signal);  // async-signal-safe; no temporary file exists yet
    }
    g_signal.store(signal);
    g_cancel.store(true);
}

/// Open MPI 4.1's mpirun, on SIGINT or SIGTERM, sends the ranks SIGCONT at once and SIGTERM only
/// odls_base_sigkill_timeout (1 s) later; it also forwards Ctrl-Z as SIGSTOP and `fg` as SIGCONT,
/// both from its own pid (strace of the ranks, docs/distributed.md). So a SIGCONT from the
/// parent while the watchdog polled a moment ago (the process was not stopped) is the start of
/// mpirun ending the job: cancel as for SIGTERM. After a stop the last poll is old: a resume.
extern "C" void on_continue(int, siginfo_t* info, void*) {
    if (info->si_code != SI_USER || info->si_pid != ::getppid()) return;
    const int64_t tick = g_watchdog_tick_ns.load();  // before the stall: the watchdog stores it first
    const int64_t stall = g_watchdog_stall_ns.load();
    const int64_t now = monotonic_ns();
    // 150 ms: the watchdog polls every 20 ms; a late poll on a loaded machine only means the
    // SIGTERM a second later does the job, never that a resumed render is cancelled.
    if (tick == 0 || now - tick > 150'000'000 || now - stall < 1'000'000'000) return;
    g_signal.store(SIGTERM);
    g_cancel.store(true);
}

/// Workers look at g_cancel only between tiles, and one tile of a legal scene (16x16 pixels,
/// 256 samples each, 256 mirror bounces, many lights) can take minutes. Nothing is written
/// while rendering, so if the render has not returned a second after a signal this ends the
/// program: the previous output is untouched and there is no temporary file yet.
class CancelWatchdog {
public:
    CancelWatchdog() : m_thread([this] { watch(); }) {}
    ~CancelWatchdog() {
        {
            std::lock_guard lock(m_mutex);
            m_done = true;
        }
        m_wake.notify_one();  // at once: a sleeping watchdog cost every render up to 20 ms
        m_thread.join();
        g_watchdog_tick_ns.store(0);  // no render to cancel any more (on_continue)
    }
    CancelWatchdog(const CancelWatchdog&) = delete;
    CancelWatchdog& operator=(const CancelWatchdog&) = delete;

private:
    /// True once the render is over; false when `interval` passed first.
    bool done_within(std::chrono::milliseconds interval) {
        std::unique_lock lock(m_mutex);
        return m_wake.wait_for(lock, interval, [this] { return m_done; });
    }

    void watch() {
        // A signal handler cannot wake a condition variable, so the signal flag is polled.
        int64_t previous = monotonic_ns();
        while (!done_within(std::chrono::milliseconds(20))) {
            const int64_t now = monotonic_ns();
            if (now - previous > 100'000'000) g_watchdog_stall_ns.store(now);  // stopped, or starved
            g_watchdog_tick_ns.store(now);
            previous = now;
            if (!g_cancel.load()) continue;
            if (done_within(std::chrono::milliseconds(900))) return;
            // Under MPI rank 0 can also be waiting on a rank that died in the middle of a message.
            std::fprintf(stderr, g_mpi_job ? "whitted: interrupted; a tile or a message from another rank did not "
                                             "arrive within a second, stopped without writing anything\n"
                                           : "whitted: interrupted; a tile did not finish within a second, "
                                             "stopped without writing anything\n");
            std::fflush(stderr);
            ::_exit(128 + g_signal.load());
        }
    }

    std::mutex m_mutex;
    std::condition_variable m_wake;
    bool m_done = false;
    std::thread m_thread;  // last: starts once the members it uses exist
};

void install_signal_handlers() {
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    if (g_mpi_job) {  // only an MPI rank has an mpirun for a parent (on_continue)
        struct sigaction on_cont {};
        on_cont.sa_sigaction = on_continue;
        on_cont.sa_flags = SA_SIGINFO | SA_RESTART;
        sigemptyset(&on_cont.sa_mask);
        sigaction(SIGCONT, &on_cont, nullptr);
    }
}

/// What the process uses for its large blocks, for --stats (choose_huge_pages).
std::string g_page_summary = "4 KiB pages";

/// Huge pages for the blocks of 2 MiB or more and Embree's, where they pay (large_blocks.cpp
/// says why): WHITTED_HUGE_PAGES=on or off decides; unset or `auto`, the first write to a
/// 4 KiB page is timed. A value it does not know is an Error (bad input).
api::Expected<void> choose_huge_pages() {
    namespace blocks = large_blocks;
    const char* setting = std::getenv("WHITTED_HUGE_PAGES");
    const std::string value = setting && *setting ? setting : "auto";
    if (value != "auto" && value != "on" && value != "off")
        return api::Error{"WHITTED_HUGE_PAGES=" + api::printable(value) + ": not one of auto, on, off"};
    bool huge = false;
    if (value == "off") {
        g_page_summary = "4 KiB pages (WHITTED_HUGE_PAGES=off)";
    } else if (!blocks::replaces_operator_new()) {
        g_page_summary = "4 KiB pages (the sanitizer's allocator)";
    } else if (!blocks::system_offers_huge_pages()) {
        g_page_summary = "4 KiB pages (transparent huge pages are 'never' on this system)";
    } else if (value == "on") {
        huge = true;
        g_page_summary = "2 MiB pages for large blocks (WHITTED_HUGE_PAGES=on)";
    } else {
        const double microseconds = blocks::first_write_microseconds();
        huge = microseconds >= blocks::huge_pages_from_microseconds;
        g_page_summary = fmt::format("{} (a 4 KiB page's first write took {:.2f} us; huge pages from {:.1f})",
                                     huge ? "2 MiB pages for large blocks" : "4 KiB pages", microseconds,
                                     blocks::huge_pages_from_microseconds);
    }
    if (huge) {
        prctl(PR_SET_THP_DISABLE, 0, 0, 0, 0);
        blocks::use_huge_pages(true);
        api::use_huge_pages(true);
    }
    return {};
}

/// --stats' account of what traces the rays: Embree's BVH, or each ray testing the scene's few
/// shapes (api::AcceleratorInfo::has_bvh).
std::string bvh_summary(const api::AcceleratorInfo& accelerator) {
    if (!accelerator.has_bvh) return "no BVH: each ray tests the scene's few shapes";
    return fmt::format("BVH {:.1f} MB ({:.1f} MB while building); Embree {}, {}-wide packets",
                       double(accelerator.bytes) / 1e6, double(accelerator.peak_bytes) / 1e6,
                       accelerator.isa.empty() ? "(its choice)" : accelerator.isa, accelerator.lane_width);
}

std::string format_duration(double seconds) {
    if (seconds < 60) return fmt::format("{:.1f}s", seconds);
    return fmt::format("{}m{:02d}s", int(seconds / 60), int(seconds) % 60);
}

/// The terminal's width in columns (80 when it does not say).
int terminal_columns() {
    winsize size{};
    if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
    return 80;
}

/// One line that fits the terminal, redrawn in place: the bar shrinks (or goes) before the
/// figures do, and a line never wraps (a wrapped line is left behind at every redraw).
void draw_progress(const api::Progress& p) {
    const double fraction = p.tiles_total ? double(p.tiles_done) / double(p.tiles_total) : 1.0;
    const double rate = p.seconds > 0 ? double(p.rays) / p.seconds / 1e6 : 0.0;
    const double eta = fraction > 0 ? p.seconds * (1 - fraction) / fraction : 0.0;
    const std::string figures =
        fmt::format("{:5.1f}%  {:7.2f} M rays/s  elapsed {}  ETA {}", 100 * fraction, rate, format_duration(p.seconds),
                    fraction > 0 ? format_duration(eta) : std::string("?"));
    const int columns = terminal_columns() - 1;  // the last column would wrap on some terminals
    const int width = std::min(30, columns - int(figures.size()) - 3);
    std::string line;
    if (width >= 5) {
        const int filled = int(fraction * width);
        line = "[" + std::string(filled, '=');
        if (filled < width) line += '>' + std::string(width - filled - 1, ' ');
        line += "] ";
    }
    line += figures;
    if (int(line.size()) > columns) line.resize(size_t(std::max(columns, 0)));
    std::fprintf(stderr, "\r%s\x1b[K", line.c_str());  // ESC[K: clear what a longer line left
    std::fflush(stderr);
}

struct RenderArguments {
    std::string scene, output = "whitted.png";
    int threads = 0;
    bool quiet = false, partial = false, stats = false;
    api::WriteOptions write;          // --half, --exr-compression, --bit-depth, --ocio-config, --display, --view
    std::vector<std::string> layers;  // --layers; empty: not given (the scene's render.layers)
    api::SceneOverrides overrides;    // --width, --height, --samples, --max-depth, --intersection
    std::string crop;                 // --crop X,Y,WIDTH,HEIGHT; empty: the whole image
};

/// --crop's X,Y,WIDTH,HEIGHT (the window's place in the image is checked with the scene).
api::Expected<api::PixelWindow> parse_crop(const std::string& text) {
    api::PixelWindow window;
    int* const fields[] = {&window.x, &window.y, &window.width, &window.height};
    const char* p = text.data();
    const char* const end = text.data() + text.size();
    for (size_t i = 0; i < 4; ++i) {
        const auto [next, error] = std::from_chars(p, end, *fields[i]);
        if (error != std::errc() || (i < 3 ? next == end || *next != ',' : next != end))
            return api::Error{"--crop: expected X,Y,WIDTH,HEIGHT in pixels (four whole numbers), not '" +
                              api::printable(text) + "'"};
        p = next + (i < 3 ? 1 : 0);
    }
    if (window.x < 0 || window.y < 0 || window.width < 1 || window.height < 1)
        return api::Error{"--crop: X and Y must be at least 0, WIDTH and HEIGHT at least 1 (got '" +
                          api::printable(text) + "')"};
    return window;
}

/// The scene named on the command line: a file, or with `-` the text on standard input (read
/// whole, at most the scene file limit; relative mesh paths are then relative to the current
/// directory, and the format is told by the first line: docs/scene-format.md).
api::Expected<api::Scene> load_scene_argument(const std::string& scene, const api::SceneOverrides& overrides) {
    if (scene != "-") return api::load_scene_file(scene, overrides, api::SceneUse::render_only);
    std::string text;
    char buffer[1 << 16];
    for (;;) {
        const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
        if (n == 0) break;
        if (n < 0) {
            if (errno == EINTR && !g_cancel.load()) continue;
            return api::Error{std::string("cannot read the scene from standard input: ") + std::strerror(errno),
                              "<stdin>"};
        }
        if (text.size() + size_t(n) > size_t(api::limits::max_scene_file_bytes))
            return api::Error{"the scene on standard input is more than " +
                                  std::to_string(api::limits::max_scene_file_bytes) + " bytes, the scene file limit",
                              "<stdin>"};
        text.append(buffer, size_t(n));
    }
    return api::load_scene_string(text, "<stdin>", overrides);
}

/// Wall-clock time of each stage, printed by --stats.
class StageTimer {
public:
    double lap() {
        const auto now = std::chrono::steady_clock::now();
        const double seconds = std::chrono::duration<double>(now - m_last).count();
        m_last = now;
        return seconds;
    }
    double total() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count(); }

private:
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now(), m_last = m_start;
};

/// `whitted render`: load, check the options, build the BVH, render, write, each through the
/// public API; the usage checks come before any work.
int run_render(const RenderArguments& args) {
    StageTimer timer;
    if (const std::string evidence = api::mpi_launch_evidence(); !evidence.empty()) {
        api::Expected<api::MpiJob> joined = api::join_mpi_job();
        if (!joined) {
            api::Error error = joined.error();
            error.message += " (this process was started as an MPI rank: " + evidence + ")";
            return report(error);
        }
        g_mpi_job.emplace(std::move(joined).value());
    }
    install_signal_handlers();
    // Usage first, in milliseconds: nothing here reads the scene.
    std::optional<api::PixelWindow> crop;
    if (!args.crop.empty()) {
        const api::Expected<api::PixelWindow> window = parse_crop(args.crop);
        if (!window) return report(window.error());
        crop = *window;
    }
    if (const auto usable = api::check_image_output(args.output, args.write, args.layers, "--layers",
                                                    args.scene != "-" ? args.scene : std::string());
        !usable)
        return report(usable.error());
    api::Expected<api::Scene> read = load_scene_argument(args.scene, args.overrides);
    if (!read) return report(read.error());
    const api::Scene& scene = *read;
    timer.lap();
    api::RenderOptions options;
    options.threads = args.threads;
    options.layers = args.layers;  // empty: the scene's render.layers
    options.crop = crop;
    options.cancel = &g_cancel;
    options.mpi_job = g_mpi_job ? &*g_mpi_job : nullptr;
    // What the scene asks that the output must allow: the scene's render.layers, unless --layers
    // was given (--layers none turns them off).
    if (args.layers.empty() && !scene.layers().empty())
        if (const auto usable = api::check_image_output(args.output, args.write, scene.layers(),
                                                        "render.layers at " + scene.layers_location());
            !usable)
            return report(usable.error());
    // Any file the scene read (a mesh, an MTL file an OBJ names), by identity: the same file
    // under another name or through a link too.
    if (const std::string input = scene.input_file_at(args.output); !input.empty())
        return report(api::Error{"refusing to write the image to '" + args.output + "': it is " + input});
    if (crop && (int64_t(crop->x) + crop->width > scene.width() || int64_t(crop->y) + crop->height > scene.height()))
        return report(api::Error{"--crop " + args.crop + " does not lie inside the " + std::to_string(scene.width()) +
                                 "x" + std::to_string(scene.height()) + " image"});
    // The rest as api::render checks it (a glazed material cannot have layers), before the BVH.
    if (const auto usable = api::check_render_options(scene, options); !usable) return report(usable.error());

    const api::Expected<api::AcceleratorInfo> accelerator = api::prepare(scene, args.threads);  // kept for render
    if (!accelerator) return report(accelerator.error());
    const double build_seconds = timer.lap();
    const bool progress_bar = !args.quiet && ::isatty(STDERR_FILENO);
    if (progress_bar)
        options.on_progress = [](const api::Progress& p) {
            draw_progress(p);
            return true;
        };
    g_exit_on_signal.store(false);  // from here on a signal cancels, and we clean up
    api::Expected<api::RenderResult> rendered = api::Error{};
    {
        const CancelWatchdog watchdog;
        rendered = api::render(scene, options);
    }
    if (progress_bar) std::fputc('\n', stderr);
    if (!rendered) return report(rendered.error());
    const api::RenderResult& result = rendered.value();
    if (g_mpi_job && g_mpi_job->rank() != 0)  // its tiles are with rank 0, which writes the image
        return result.cancelled ? 128 + (g_signal.load() ? g_signal.load() : SIGINT) : exit_ok;
    if (g_mpi_job && !args.quiet)
        std::fprintf(stderr, "whitted: the tiles were rendered by %d MPI rank(s) (%s)\n", g_mpi_job->size(),
                     g_mpi_job->thread_support().c_str());
    timer.lap();

    // The scene's file name only: a file sent on should not carry this machine's paths.
    api::WriteOptions write = args.write;
    const uint64_t rays = result.stats.camera_rays + result.stats.shadow_rays + result.stats.reflected_rays;
    write.metadata = {
        {"whitted:scene", std::filesystem::path(args.scene).filename().string()},
        {"whitted:settings",
         fmt::format("{}x{}{}, {} sample(s)/pixel, max depth {}, intersection {}", scene.width(), scene.height(),
                     crop ? fmt::format(" cropped to {}x{} at {},{}", crop->width, crop->height, crop->x, crop->y) : "",
                     scene.samples() * scene.samples(), scene.max_depth(), scene.intersection())},
        {"whitted:render_seconds", fmt::format("{:.3f}", result.stats.seconds)},
        {"whitted:rays", std::to_string(rays)}};
    if (result.cancelled) {
        const int signal = g_signal.load();
        if (args.partial) {
            write.metadata.push_back({"whitted:partial", "true: interrupted; unfinished tiles are black"});
            if (const auto written = api::write_image(result.image, args.output, write); !written)
                return report(written.error());
            std::fprintf(stderr, "whitted: interrupted; partial image (unfinished tiles black) written to %s\n",
                         args.output.c_str());
        } else {
            std::fprintf(stderr, "whitted: interrupted; nothing written (%s left as it was)\n", args.output.c_str());
        }
        return 128 + (signal ? signal : SIGINT);
    }
    if (const auto written = api::write_image(result.image, args.output, write); !written)
        return report(written.error());
    const double write_seconds = timer.lap();
    // Radiance past the largest float is +inf in the image, as IEEE arithmetic has it: said,
    // because only a scene of enormous colours, intensities or mirror weights gets there.
    const size_t beyond_float = size_t(
        std::count_if(result.image.rgb.begin(), result.image.rgb.end(), [](float value) { return std::isinf(value); }));
    if (beyond_float > 0)
        std::fprintf(stderr,
                     "whitted: warning: %zu pixel value(s) exceed the largest float (about 3.4e38) and are "
                     "stored as +inf (clipped to 1 in PNG, JPEG and TIFF): the scene's colours or intensities "
                     "are that large\n",
                     beyond_float);
    const double total = timer.total();
    const api::SceneCounts counts = scene.counts();
    if (args.stats)
        std::fprintf(
            stderr,
            "whitted: stages: read (parse, validate, load meshes) %.3fs, build BVH %.3fs, render %.3fs, write "
            "%.3fs; "
            "%zu triangles, %zu spheres, %zu boxes, %zu planes, %zu lights, %zu instances (%zu triangles seen); "
            "%s; memory: %s\n",
            scene.read_seconds(), build_seconds, result.stats.seconds, write_seconds, counts.triangles, counts.spheres,
            counts.boxes, counts.planes, counts.lights, counts.instances, counts.instanced_triangles,
            bvh_summary(*accelerator).c_str(), g_page_summary.c_str());
    if (!args.quiet)
        std::fprintf(
            stderr,
            "whitted: %dx%d%s, %d sample(s)/pixel, %u thread(s): render %.3fs (total %.3fs), %.2f M "
            "rays (camera %.2f, shadow %.2f, reflected %.2f), %.1f M rays/s -> %s\n",
            scene.width(), scene.height(),
            crop ? fmt::format(" cropped to {}x{} at {},{}", crop->width, crop->height, crop->x, crop->y).c_str() : "",
            scene.samples() * scene.samples(),
            args.threads > 0 ? unsigned(args.threads) : std::thread::hardware_concurrency(), result.stats.seconds,
            total, rays / 1e6, result.stats.camera_rays / 1e6, result.stats.shadow_rays / 1e6,
            result.stats.reflected_rays / 1e6, result.stats.seconds > 0 ? rays / result.stats.seconds / 1e6 : 0.0,
            args.output.c_str());
    return exit_ok;
}

/// `whitted convert`: the scene as loaded (its description, not the file read again) in the
/// format the output's extension names.
int run_convert(const std::string& scene_path, const std::string& output) {
    // SIGINT/SIGTERM end the program at once (130/143): the files are written unnamed and only
    // named when complete, so there is nothing to clean up.
    install_signal_handlers();
    // Usage errors before any work: where the file(s) cannot go.
    if (const auto usable = api::check_convert_output(output, scene_path); !usable) return report(usable.error());
    const api::Expected<api::Scene> scene = api::load_scene_file(scene_path);
    if (!scene) return report(scene.error());
    const api::Expected<std::vector<std::string>> written = api::convert(*scene, output);
    if (!written) return report(written.error());
    if (written->size() == 1)
        std::fprintf(stderr, "whitted: wrote %s\n", written->front().c_str());
    else
        std::fprintf(stderr, "whitted: wrote %s and %s\n", written->front().c_str(), written->back().c_str());
    return exit_ok;
}

int run_check_command(const std::string& scene_path, api::CheckOptions options) {
    // Until the check has created its first file or directory a signal ends the program at once
    // (g_exit_on_signal, cleared by api::check); from then on it stops POV-Ray, the temporary
    // directories are removed and the exit status is 130/143.
    options.cancel = &g_cancel;
    options.nothing_created_yet = &g_exit_on_signal;
    install_signal_handlers();
    const api::Expected<api::CheckResult> checked = api::check(scene_path, options);
    if (!checked) {
        if (checked.error().kind != api::Error::Kind::cancelled) return report(checked.error());
        std::fprintf(stderr, "whitted: %s\n", checked.error().message.c_str());
        return 128 + (g_signal.load() ? g_signal.load() : SIGINT);
    }
    return checked->passed ? exit_ok : exit_failure;
}

int run_compare_command(const std::string& first, const std::string& second, const api::PassRule& rule, bool clip) {
    const api::Expected<api::Comparison> compared = api::compare_image_files(first, second, rule, clip);
    if (!compared) return report(compared.error());
    if (!compared->first_meaning.empty())
        std::printf("%s: %s\n%s: %s\n", first.c_str(), compared->first_meaning.c_str(), second.c_str(),
                    compared->second_meaning.c_str());
    std::printf("%s\n", compared->verdict.c_str());
    return compared->passed ? exit_ok : exit_failure;
}

int run_colour(bool list, const std::string& config, const std::string& write_config) {
    if (!config.empty() && !list) return report(api::Error{"--ocio-config goes with --list"});
    if (!write_config.empty()) {
        if (const auto written = api::write_colour_config(write_config); !written) return report(written.error());
        std::fprintf(stderr, "whitted: wrote the built-in OpenColorIO config to %s\n", write_config.c_str());
    }
    if (list) {
        const api::Expected<std::string> text = api::describe_colour_config(config);
        if (!text) return report(text.error());
        std::fputs(text->c_str(), stdout);
    }
    return exit_ok;
}

/// `whitted --version`: the program's version and, since it decides which of Embree's code
/// paths run, the instruction sets Embree can use here and the one in use.
std::string version_text() {
    std::string text = std::string("whitted ") + api::version();
    const api::Expected<api::EmbreeInfo> info = api::embree_info();
    if (!info) return text + "\nEmbree: " + info.error().what();
    std::string isas;
    for (const std::string& name : info->isas) isas += (isas.empty() ? "" : " ") + name;
    text += "\nEmbree " + info->version + "; instruction sets this CPU can run: " + isas;
    text += "\nin use: " + info->isa_in_use + (info->isa_from_environment ? " (WHITTED_EMBREE_ISA)" : " (the widest)") +
            ", " + std::to_string(info->lane_width) + "-wide packets";
    return text;
}

/// The folder holding the docs/ and examples/ that --help names: PREFIX/share/whitted beside an
/// installed program, else the source checkout a build tree was made from; empty when neither
/// is there (a program copied elsewhere), and --help then names them alone.
std::string documentation_root() {
    std::error_code error;
    const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error) {
        const std::filesystem::path installed = program.parent_path().parent_path() / "share" / "whitted";
        if (std::filesystem::is_directory(installed / "docs", error)) return installed.string();
    }
#ifdef WHITTED_SOURCE_DIR
    if (std::filesystem::is_directory(std::filesystem::path(WHITTED_SOURCE_DIR) / "docs", error))
        return WHITTED_SOURCE_DIR;
#endif
    return {};
}

}  // namespace

int main(int argc, char** argv) {
    // Transparent huge pages off for this process until a command that traces rays finds that
    // they pay here (choose_huge_pages). Embree asks for them (madvise) for all its BVH memory.
    // Where a virtual machine's host takes back the guest's free memory in 2 MiB blocks
    // (virtio-balloon free page reporting), a huge page is exactly such a block and its first
    // touch costs the host 512 faults: BVH builds ran several times slower (docs/performance.md,
    // "Design choices and what they cost").
    prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0);
    // Freed blocks under 1 MiB stay in malloc's heaps for the next one (large_blocks.cpp).
    whitted::large_blocks::keep_freed_memory();
    // Past a file size limit (ulimit -f) a write fails with EFBIG, which every command reports and
    // cleans up after, instead of SIGXFSZ killing the process with a temporary file left.
    std::signal(SIGXFSZ, SIG_IGN);
    CLI::App app{
        "Whitted: an offline ray tracer for the classic lecture shading model\n"
        "  L = ka*Ia + sum_i [kd*I_i*max(0,n.l_i) + ks*I_i*max(0,n.h_i)^p] + km*L(r)\n"
        "checked pixel by pixel against POV-Ray 3.7.",
        "whitted"};
    app.set_version_flag("--version", version_text);
    app.require_subcommand(1);
    // CLI11's own refusals in the form of every other error, naming the command's --help. Set
    // before the commands are added: each copies it when it is made.
    app.failure_message([](const CLI::App* top, const CLI::Error& e) {
        std::string help = "whitted";
        for (const CLI::App* command : top->get_subcommands()) help += " " + command->get_name();
        return "whitted: error: " + std::string(e.what()) + " (" + help + " --help)\n";
    });
    app.footer(
        "Exit status: 0 success; 1 failure while rendering or checking (or images disagree);\n"
        "2 bad input or usage; 130/143 interrupted by SIGINT/SIGTERM.\n"
        "Environment: OCIO (colour config), WHITTED_POVRAY (POV-Ray for check),\n"
        "WHITTED_EMBREE_ISA=sse2|sse4.2|avx|avx2|avx512 (force Embree's instruction set; the\n"
        "image is the same bit for bit, only the speed differs; --version lists this CPU's).\n"
        "WHITTED_HUGE_PAGES=auto|on|off (2 MiB pages for large blocks: auto, where a 4 KiB page's\n"
        "first write is dear; --stats says which; the image is the same either way).\n"
        "Under mpirun or srun, `render` shares the tiles out among the ranks (WHITTED_MPI=0: don't;\n"
        "docs/distributed.md).\n"
        "Scene format: docs/scene-format.md. Examples: examples/lecture/.\n"
        "Cornell CS4620 course scenes (.xml, with .msh meshes) render and convert directly, with the\n"
        "course's conventions: docs/course-format.md (its images: --display 'Gamma 2.2').\n"
        "NFF scenes (.nff, Eric Haines' SPD databases) render, convert and check directly: docs/nff.md." +
        (documentation_root().empty() ? std::string()
                                      : "\nThe docs/ and examples/ named here are in " + documentation_root() + "/."));

    // A path given as '' is a mistake (an unset shell variable, say), not "no path": without this
    // `--write-config ''` would do nothing and succeed, `--report ''` would write no report.
    const CLI::Validator not_empty(
        [](std::string& value) { return value.empty() ? std::string("an empty value; give a name") : std::string(); },
        "", "not_empty");
    // The scene, or - for standard input, with one reason when it is neither.
    const CLI::Validator scene_or_stdin(
        [](std::string& path) { return path == "-" ? std::string() : CLI::ExistingFile(path); }, "", "scene");

    RenderArguments render_args;
    CLI::App* render_cmd = app.add_subcommand(
        "render", "Render a scene file (YAML or JSON, format v1; a course .xml scene; an NFF .nff scene) to an image");
    render_cmd->add_option("scene", render_args.scene, "Scene file, or - to read the scene from standard input")
        ->required()
        ->check(scene_or_stdin);
    render_cmd
        ->add_option("-o,--output", render_args.output,
                     "Output image: .exr is linear float (scene-referred); .png/.jpg/.tif go through the "
                     "display transform (--display, --view, --ocio-config)")
        ->capture_default_str()
        ->check(not_empty);
    render_cmd->add_option("-t,--threads", render_args.threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(0, 4096));
    render_cmd->add_flag("-q,--quiet", render_args.quiet, "No progress bar and no summary line");
    render_cmd->add_flag("--half", render_args.write.half, "EXR: write half floats instead of 32-bit floats");
    render_cmd
        ->add_option("--exr-compression", render_args.write.exr_compression,
                     "EXR compression, all lossless: none (the default, fastest to write), zip, zips, piz, rle")
        ->check(CLI::IsMember({"none", "zip", "zips", "piz", "rle"}));
    render_cmd
        ->add_option("--bit-depth", render_args.write.bit_depth,
                     "PNG/TIFF bits per channel, 8 or 16 (default: PNG 8, TIFF 16; JPEG is 8 only)")
        ->check(CLI::IsMember({8, 16}));
    render_cmd
        ->add_option("--ocio-config", render_args.write.ocio_config,
                     "PNG/JPEG/TIFF: OpenColorIO config file (default: $OCIO, else the built-in config; "
                     "`whitted colour --list` shows it)")
        ->check(not_empty);
    render_cmd
        ->add_option("--display", render_args.write.display,
                     "PNG/JPEG/TIFF: OCIO display, e.g. sRGB, 'Gamma 2.2', BT.1886, 'Display P3' "
                     "(default: the config's default)")
        ->check(not_empty);
    render_cmd
        ->add_option("--view", render_args.write.view,
                     "PNG/JPEG/TIFF: OCIO view, e.g. Standard, Raw (default: the display's default)")
        ->check(not_empty);
    render_cmd->add_flag("--stats", render_args.stats,
                         "Print the time of each stage (parse, load, BVH, render, write) and the BVH's memory");
    render_cmd->add_flag("--partial", render_args.partial,
                         "If interrupted, still write what was finished (marked partial in the metadata)");
    render_cmd
        ->add_option("--width", render_args.overrides.width,
                     "Image width in pixels, replacing image.width (alone: the height keeps the aspect ratio)")
        ->check(CLI::Range(1, int(api::limits::max_image_side)));
    render_cmd
        ->add_option("--height", render_args.overrides.height,
                     "Image height in pixels, replacing image.height (alone: the width keeps the aspect ratio)")
        ->check(CLI::Range(1, int(api::limits::max_image_side)));
    render_cmd
        ->add_option("--samples", render_args.overrides.samples,
                     "Samples per pixel side, replacing image.samples (n: n*n rays per pixel)")
        ->check(CLI::Range(1, int(api::limits::max_samples)));
    render_cmd
        ->add_option("--max-depth", render_args.overrides.max_depth,
                     "Mirror and refraction bounces, replacing render.max_depth")
        ->check(CLI::Range(1, int(api::limits::max_depth)));
    render_cmd
        ->add_option("--intersection", render_args.overrides.intersection,
                     "How hits are decided, replacing render.intersection: exact (the default) or povray "
                     "(POV-Ray 3.7's decisions, as `whitted check` renders)")
        ->check(CLI::IsMember({"exact", "povray"}));
    render_cmd->add_option("--crop", render_args.crop,
                           "Render only this window of the image, X,Y,WIDTH,HEIGHT in pixels from the top-left "
                           "corner: the output is WIDTH x HEIGHT, the same pixels as the whole render");

    render_cmd
        ->add_option(
            "--layers", render_args.layers,
            "EXR only: write render layers as extra channels, 'all' or a comma-separated list of: " +
                api::layer_choices() +
                " (docs/layers.md); overrides the scene's render.layers, 'none' turns them off. The "
                "beauty R, G, B is then the float sum of ambient, diffuse, specular, mirror, transmission, background")
        ->delimiter(',');

    std::string explain_scene, explain_pixel_text;
    bool explain_json = false, explain_summary = false;
    int explain_threads = 0;
    api::SceneOverrides explain_overrides;  // --intersection
    CLI::App* explain_cmd = app.add_subcommand(
        "explain", "Print every term of one pixel's equation, as the render computes it (docs/layers.md)");
    explain_cmd->add_option("scene", explain_scene, "Scene file")->required()->check(CLI::ExistingFile);
    explain_cmd
        ->add_option("--pixel", explain_pixel_text, "The pixel: X,Y (column, row from the top-left corner, 0-based)")
        ->required();
    CLI::Option* explain_json_flag =
        explain_cmd->add_flag("--json", explain_json, "Print JSON (docs/explain.schema.json) instead of text");
    explain_cmd
        ->add_flag("--summary", explain_summary,
                   "Print the pixel in a dozen lines: its first hit, each term averaged over the samples, the pixel")
        ->excludes(explain_json_flag);
    explain_cmd
        ->add_option("--intersection", explain_overrides.intersection,
                     "How hits are decided, replacing render.intersection: exact (the default) or povray "
                     "(POV-Ray 3.7's decisions, as `whitted check` renders)")
        ->check(CLI::IsMember({"exact", "povray"}));
    explain_cmd->add_option("-t,--threads", explain_threads, "Threads for building the BVH (default: all cores)")
        ->check(CLI::Range(0, 4096));

    LiveArguments live_args;
    bool live_no_open = false;
    CLI::App* live_cmd = app.add_subcommand(
        "live",
        "Serve a page on 127.0.0.1 with the scene rendered and sliders for its materials and lights, "
        "re-rendered as they move and when the file changes (docs/live.md)");
    live_cmd->add_option("scene", live_args.scene, "Scene file")->required()->check(CLI::ExistingFile);
    live_cmd->add_option("--port", live_args.port, "Port on 127.0.0.1 (default: a free one, printed)")
        ->check(CLI::Range(1, 65535));
    live_cmd->add_flag("--no-open", live_no_open, "Print the address only; do not open it in a browser");
    live_cmd->add_option("-t,--threads", live_args.threads, "Worker threads (default: all cores)")
        ->check(CLI::Range(0, 4096));

    std::string convert_scene, convert_output;
    CLI::App* convert_cmd = app.add_subcommand("convert", "Convert a scene to another renderer's format");
    convert_cmd->add_option("scene", convert_scene, "Scene file")->required()->check(CLI::ExistingFile);
    convert_cmd
        ->add_option("output", convert_output,
                     "Output file; the extension picks the format: .pov = POV-Ray 3.7 (+ a matching .ini), "
                     ".yaml/.yml = Whitted's own format (e.g. from a course .xml or an NFF .nff scene)")
        ->required();

    std::string check_scene;
    api::CheckOptions check_options;
    check_options.quiet = false;
    CLI::App* check_cmd = app.add_subcommand(
        "check", "Render a scene with Whitted and with POV-Ray (converted) and compare them pixel by pixel");
    check_cmd->add_option("scene", check_scene, "Scene file")->required()->check(CLI::ExistingFile);
    check_cmd
        ->add_option("--report", check_options.report_dir,
                     "Write images, a difference heat map, metrics.json and report.html (open it from the disk: "
                     "wipe, zoom, pixel probe; docs/validation.md) into this directory")
        ->check(not_empty);
    check_cmd
        ->add_option("--tolerance", check_options.tolerance_codes, "Per-channel tolerance in 16-bit codes (1/65535)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    check_cmd->add_option("--min-fraction", check_options.min_fraction, "Share of pixels that must be within tolerance")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    check_cmd
        ->add_option("--max-error", check_options.max_error_codes,
                     "Hard cap: no channel of any pixel may differ by more than this many 16-bit codes")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    check_cmd->add_option("-t,--threads", check_options.threads, "Worker threads for Whitted (default: all cores)")
        ->check(CLI::Range(0, 4096));
    check_cmd->add_flag("-q,--quiet", check_options.quiet, "Print only the verdict line");
    check_cmd->add_flag("--terms", check_options.terms,
                        "Check term by term: the scene with only ambient, only diffuse, only specular, and each "
                        "light alone (several lights), each against POV-Ray; the last line names the terms "
                        "that disagree");
    check_cmd
        ->add_option("--layers", check_options.layers,
                     "Render Whitted's image with these render layers (as `render --layers`) and compare its "
                     "beauty, then the float sum of the colour layers")
        ->delimiter(',');
    CLI::Option* povray_image_option =
        check_cmd
            ->add_option("--povray-image", check_options.povray_image,
                         "Do not run POV-Ray: compare with this stored POV-Ray 16-bit PNG of the converted scene "
                         "(samples*W x samples*H), made at --exposure")
            ->check(CLI::ExistingFile);
    check_cmd
        ->add_option("--exposure", check_options.exposure,
                     "With --povray-image: the exposure it was rendered at (a power of two <= 1; check prints it)")
        ->needs(povray_image_option)
        ->check(CLI::Range(std::numeric_limits<double>::min(), 1.0));

    std::string colour_config, colour_write;
    bool colour_list = false;
    CLI::App* colour_cmd = app.add_subcommand(
        "colour", "Show the OpenColorIO displays and views, or write the built-in config for other programs");
    colour_cmd->alias("color");
    colour_cmd->add_flag("--list", colour_list,
                         "Print each display and view, the colour space it writes and what that means");
    colour_cmd
        ->add_option("--ocio-config", colour_config,
                     "With --list: this config (default: $OCIO, else the built-in config)")
        ->check(not_empty);
    colour_cmd
        ->add_option("--write-config", colour_write,
                     "Write the built-in config to this .ocio file (for oiiotool, Nuke, Blender, ...)")
        ->check(not_empty);
    colour_cmd->require_option(1, 2);

    std::string compare_first, compare_second;
    api::PassRule compare_rule;
    bool compare_clip = false;
    CLI::App* compare_cmd =
        app.add_subcommand("compare",
                           "Compare two images pixel by pixel (e.g. a Whitted EXR and a POV-Ray PNG), each first "
                           "turned into linear Rec.709 from its colour metadata");
    compare_cmd->add_option("first", compare_first, "Image")->required()->check(CLI::ExistingFile);
    compare_cmd->add_option("second", compare_second, "Image of the same size")->required()->check(CLI::ExistingFile);
    compare_cmd
        ->add_option("--tolerance", compare_rule.tolerance_codes, "Per-channel tolerance in 16-bit codes (1/65535)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    compare_cmd
        ->add_option("--min-fraction", compare_rule.min_fraction, "Share of pixels that must be within tolerance")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    compare_cmd
        ->add_option("--max-error", compare_rule.max_error_codes,
                     "Hard cap: no channel of any pixel may differ by more than this many 16-bit codes")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    compare_cmd->add_flag("--clip", compare_clip, "Clip both images to [0, 1] first (PNG files clip at 1)");

    // A mistyped command gets its nearest name (CLI11 would say only that one is required).
    if (argc > 1 && argv[1][0] != '-') {
        std::vector<std::string> commands;
        bool known = false;  // by name or alias ("color")
        for (const CLI::App* command : app.get_subcommands({})) {
            commands.push_back(command->get_name());
            known = known || command->check_name(argv[1]);
        }
        if (!known) {
            std::string list;
            for (const std::string& name : commands) list += (list.empty() ? "" : ", ") + name;
            return report(api::Error{"unknown command '" + api::printable(argv[1]) + "'" +
                                     api::did_you_mean(argv[1], commands) + "; the commands are " + list +
                                     " (whitted --help)"});
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : exit_bad_input;
    }

    // WHITTED_EMBREE_ISA, checked before any work: a name Embree does not know, or an instruction
    // set this CPU lacks, is a usage error, not a failure after parsing and loading.
    if (*render_cmd || *check_cmd || *explain_cmd || *live_cmd) {
        if (const auto usable = api::check_embree_isa(); !usable) return report(usable.error());
        if (const auto chosen = choose_huge_pages(); !chosen) return report(chosen.error());
    }
    if (*live_cmd) {
        live_args.open_browser = !live_no_open;
        return run_live(live_args);
    }
    // What a command's own code throws (out of memory, say) is reported as the library reports
    // its errors, by run_reporting.
    if (*explain_cmd)
        return run_reporting("explaining a pixel of " + explain_scene, [&] {
            return run_explain(explain_scene, explain_pixel_text, explain_overrides, explain_json, explain_summary,
                               explain_threads);
        });
    if (*render_cmd) {
        const int code = run_reporting("rendering " + render_args.scene, [&] { return run_render(render_args); });
        // Every rank finalizes only after success: a rank that failed exits without, so that
        // mpirun ends the whole job instead of the others waiting for it (docs/distributed.md).
        if (code == exit_ok && g_mpi_job) g_mpi_job->finalize();
        // The image is on disk and the summary printed: skip tearing down the BVH, the image
        // buffers and the thread pools, which took up to 30 ms of a 0.15 s render. Nothing is
        // left to flush but stdio.
        std::fflush(nullptr);
        std::_Exit(code);
    }
    if (*convert_cmd)
        return run_reporting("converting " + convert_scene, [&] { return run_convert(convert_scene, convert_output); });
    if (*colour_cmd)
        return run_reporting("listing the colour config",
                             [&] { return run_colour(colour_list, colour_config, colour_write); });
    if (*compare_cmd)
        return run_reporting("comparing " + compare_first + " and " + compare_second, [&] {
            return run_compare_command(compare_first, compare_second, compare_rule, compare_clip);
        });
    return run_reporting("checking " + check_scene, [&] { return run_check_command(check_scene, check_options); });
}
