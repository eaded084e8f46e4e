// SPDX-License-Identifier: MIT
#pragma once

// Whitted's public C++ API (docs/library.md): load or build a scene, render it, write the image
// through the colour pipeline, convert it to POV-Ray SDL, check it against POV-Ray.
//
// This header and the ones it includes (whitted/image.h, whitted/progress.h, whitted/version.h) are all a caller
// needs: standard C++20 only, no Embree, TBB, YAML or OpenColorIO types. Every function that can
// fail on the caller's input returns an Expected: the value, or an Error saying what is wrong and
// where (FILE:LINE:COL). Nothing here throws for bad input; only misuse (value() of an error)
// throws.

#include "whitted/image.h"
#include "whitted/progress.h"
#include "whitted/version.h"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if defined(_WIN32)
#define WHITTED_API
#else
#define WHITTED_API __attribute__((visibility("default")))
#endif

namespace whitted::api {

/// The library's version, "MAJOR.MINOR.PATCH" (the same as WHITTED_VERSION_STRING of the
/// headers it was built with, and as `whitted --version`).
WHITTED_API const char* version();

/// What went wrong, and where: the scene file (or "<string>", or "<SceneBuilder>" with the
/// number of the builder call as the line) and its 1-based line and column, 0 when unknown.
struct Error {
    std::string message;    ///< without the location
    std::string file = {};  ///< the file the error is in, if any
    int line = 0, column = 0;
    /// bad_input: the caller's scene or options are wrong (`whitted` exits 2); failure: it went
    /// wrong while working, e.g. writing or out of memory (exit 1); cancelled: a render stopped by
    /// RenderOptions::cancel or the progress callback.
    enum class Kind { bad_input, failure, cancelled };
    Kind kind = Kind::bad_input;

    /// "FILE:LINE:COL: message" (or "FILE: message", or the message alone), as `whitted` prints it.
    std::string what() const {
        if (file.empty()) return message;
        if (line <= 0) return file + ": " + message;
        return file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message;
    }
};

/// `whitted`'s exit statuses (its --help footer); 128 + the signal when interrupted.
enum ExitStatus : int { exit_ok = 0, exit_failure = 1, exit_bad_input = 2 };

/// The exit status `whitted` gives for the error: 2 for bad input, 1 otherwise.
inline int exit_status(const Error& error) {
    return error.kind == Error::Kind::bad_input ? exit_bad_input : exit_failure;
}

/// The exception being handled, as an Error by the rules every function here follows
/// (std::invalid_argument is bad input, running out of memory a failure "while `doing`", ...),
/// for a program's own code over the API; call only inside a catch block.
WHITTED_API Error error_of_current_exception(const std::string& doing);

/// Thrown only by Expected::value() on an error (a programming mistake: test first).
class BadExpectedAccess : public std::runtime_error {
public:
    explicit BadExpectedAccess(Error error) : std::runtime_error(error.what()), m_error(std::move(error)) {}
    const Error& error() const { return m_error; }

private:
    Error m_error;
};

/// A value or an Error (C++20 has no std::expected yet; this is the small part of it we need).
template <class T>
class Expected {
public:
    Expected(T value) : m_value(std::move(value)) {}      // NOLINT: implicit, like std::expected
    Expected(Error error) : m_error(std::move(error)) {}  // NOLINT

    bool has_value() const { return m_value.has_value(); }
    explicit operator bool() const { return has_value(); }
    T& value() & { return check(), *m_value; }
    const T& value() const& { return check(), *m_value; }
    T&& value() && { return check(), std::move(*m_value); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    /// The error; an empty one when there is a value.
    const Error& error() const { return m_error; }

private:
    void check() const {
        if (!m_value) throw BadExpectedAccess(m_error);
    }
    std::optional<T> m_value;
    Error m_error;
};

template <>
class Expected<void> {
public:
    Expected() = default;
    Expected(Error error) : m_ok(false), m_error(std::move(error)) {}  // NOLINT
    bool has_value() const { return m_ok; }
    explicit operator bool() const { return m_ok; }
    void value() const {
        if (!m_ok) throw BadExpectedAccess(m_error);
    }
    const Error& error() const { return m_error; }

private:
    bool m_ok = true;
    Error m_error;
};

/// How many of each thing a loaded scene holds.
struct SceneCounts {
    size_t triangles = 0;  ///< of the meshes and triangles, each mesh once
    size_t spheres = 0, boxes = 0, planes = 0, lights = 0;
    size_t instances = 0;            ///< placements of a mesh
    size_t instanced_triangles = 0;  ///< triangles as the instances place them
};

/// A loaded, validated scene, ready to render (many times, from several threads at once). The
/// acceleration structure (BVH) is built on the first render and kept. Move-only.
class WHITTED_API Scene {
public:
    struct Impl;  ///< private (renderer/api/api_internal.h)
    explicit Scene(std::unique_ptr<Impl> impl);
    Scene(Scene&&) noexcept;
    Scene& operator=(Scene&&) noexcept;
    ~Scene();

    int width() const;    ///< image.width, pixels
    int height() const;   ///< image.height
    int samples() const;  ///< image.samples: n×n rays per pixel
    int max_depth() const;
    /// The file it was read from, "<string>" or "<SceneBuilder>".
    const std::string& path() const;
    /// render.layers as written in the scene (empty: none asked for).
    std::vector<std::string> layers() const;
    /// Where render.layers is written, "FILE:LINE:COL" (for messages); empty when it is not.
    std::string layers_location() const;
    /// render.intersection: "exact" or "povray" (how hits are decided).
    std::string intersection() const;
    /// The mesh files the scene read, as resolved paths.
    std::vector<std::string> mesh_files() const;
    /// What the scene holds once loaded (a mesh's triangles counted once per mesh).
    SceneCounts counts() const;
    /// Wall time load_scene_* took: reading, validating and loading the meshes, seconds.
    double read_seconds() const;
    /// What `path` is among the files read to load the scene (the scene file, its meshes and
    /// MTL files, by identity: under any name or through a link), e.g. "the mesh file 'm.obj'";
    /// empty when it is none of them or does not exist. For refusing an output over an input.
    std::string input_file_at(const std::string& path) const;

private:
    friend const Impl& impl_of(const Scene& scene);  ///< the library's own access
    std::unique_ptr<Impl> m_impl;
};

/// Settings given from outside the scene, as `whitted render --width ... --intersection` gives
/// them: each replaces the file's value before the scene is checked, so the file's limits hold
/// (an Error names the setting). A width without a height, or a height without a width, keeps the
/// scene's aspect ratio, the other side rounded to the nearest pixel.
struct SceneOverrides {
    std::optional<int> width, height;
    std::optional<int> samples;               ///< image.samples: n×n rays per pixel, 1..16
    std::optional<int> max_depth;             ///< render.max_depth, 1..256
    std::optional<std::string> intersection;  ///< render.intersection: "exact" or "povray"
};

/// What a loaded scene will be used for.
enum class SceneUse {
    /// Anything: the Scene keeps the description it was read from, and to_povray/write_povray
    /// convert that (never the file again, which may have changed since).
    any,
    /// Rendering only: each object's description is let go once it is validated, so a file of a
    /// million spheres costs bytes per sphere, not the description's hundreds (docs/performance.md,
    /// "One pass"); to_povray/write_povray of such a Scene are an Error.
    render_only,
};

/// Reads and validates a scene file: YAML or JSON scene format v1 (docs/scene-format.md), a
/// Cornell CS4620 course .xml scene (docs/course-format.md) or an NFF scene (docs/nff.md). Mesh
/// files are read too. The file is read once.
WHITTED_API Expected<Scene> load_scene_file(const std::string& path, const SceneOverrides& overrides = {},
                                            SceneUse use = SceneUse::any);
/// The same from text in memory; `name` stands for the file in messages, and relative mesh
/// paths are resolved against its directory. The format is the one `name`'s extension says
/// (.xml, .nff; .yaml, .yml, .json), else the one the text's first line says (NFF entities,
/// XML's `<`, else YAML).
WHITTED_API Expected<Scene> load_scene_string(const std::string& text, const std::string& name = "<string>",
                                              const SceneOverrides& overrides = {});

/// A point, direction or RGB colour.
struct Vec3 {
    double x = 0, y = 0, z = 0;
};

/// The lecture's material: L = ka·Ia + Σ[kd·I·max(0,n·l) + ks·I·max(0,n·h)^p] + km·L(r).
struct Material {
    Vec3 ka, kd, ks;
    double p = 1;  ///< Phong exponent (Blinn-Phong half vector h)
    Vec3 km;       ///< mirror weight
};

/// A scene built in code: each call adds what the scene file's key of the same name would say
/// (docs/scene-format.md); build() validates it exactly like a file. An Error from build()
/// names "<SceneBuilder>" and the number of the call (1 = the first call) as its line.
class WHITTED_API SceneBuilder {
public:
    SceneBuilder();
    SceneBuilder(SceneBuilder&&) noexcept;
    SceneBuilder& operator=(SceneBuilder&&) noexcept;
    ~SceneBuilder();

    SceneBuilder& image(int width, int height, int samples = 1);
    SceneBuilder& background(Vec3 color);
    /// A perspective camera; fov is the horizontal field of view in degrees.
    SceneBuilder& camera(Vec3 eye, Vec3 look_at, Vec3 up = {0, 1, 0}, double fov_degrees = 45);
    SceneBuilder& ambient(Vec3 intensity);  ///< Ia (default 1, 1, 1)
    SceneBuilder& max_depth(int depth);     ///< mirror bounces (default 5)
    SceneBuilder& point_light(Vec3 position, Vec3 intensity);
    SceneBuilder& directional_light(Vec3 direction, Vec3 intensity);
    SceneBuilder& sphere(Vec3 center, double radius, const Material& material);
    SceneBuilder& plane(Vec3 point, Vec3 normal, const Material& material);
    SceneBuilder& box(Vec3 min, Vec3 max, const Material& material);
    SceneBuilder& triangle(Vec3 a, Vec3 b, Vec3 c, const Material& material);

    Expected<Scene> build() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/// A rectangle of pixels: its top-left corner (column, row from the top-left, 0-based) and size.
struct PixelWindow {
    int x = 0, y = 0, width = 0, height = 0;
};

/// Why this process looks like one rank of an MPI job (e.g. "OMPI_COMM_WORLD_SIZE=4"), or ""
/// when it does not; $WHITTED_MPI=0 says never, 1 always (docs/distributed.md).
WHITTED_API std::string mpi_launch_evidence();

/// This process as one rank of an MPI job (docs/distributed.md): with RenderOptions::mpi_job,
/// render() shares the tiles out among the ranks. MPI itself lives in a plug-in
/// (lib/libwhitted_mpi.so), loaded by join_mpi_job() only. Move-only.
class WHITTED_API MpiJob {
public:
    struct Impl;  ///< private (renderer/api/api_internal.h)
    explicit MpiJob(std::unique_ptr<Impl> impl);
    MpiJob(MpiJob&&) noexcept;
    MpiJob& operator=(MpiJob&&) noexcept;
    ~MpiJob();

    int rank() const;  ///< 0: the rank that receives every tile and writes the image
    int size() const;  ///< the number of ranks
    /// The thread support MPI_Init_thread gave, e.g. "MPI_THREAD_MULTIPLE".
    std::string thread_support() const;
    /// MPI_Finalize: once, after the last render, on the thread that joined. A rank that failed
    /// should exit without it, so that mpirun ends the whole job.
    void finalize();

private:
    friend const Impl& impl_of(const MpiJob& job);  ///< the library's own access
    std::unique_ptr<Impl> m_impl;
};

/// Loads the MPI plug-in and initialises MPI; an Error (failure) says where the plug-in was
/// looked for when it cannot.
WHITTED_API Expected<MpiJob> join_mpi_job();

struct RenderOptions {
    int threads = 0;  ///< 0 = all cores; the image is bit-identical for any number
    /// Render only this window of the image (`whitted render --crop`): the result is an image of
    /// the window's size whose pixels are the whole render's, bit for bit. It must lie inside
    /// the image.
    std::optional<PixelWindow> crop;
    /// Render layers (docs/layers.md), as `whitted render --layers`: "all", or names such as
    /// "diffuse", "N". Empty: the scene's render.layers; {"none"}: none.
    std::vector<std::string> layers;
    /// Called a few times a second from a thread of the render's own, and once at the end.
    /// Returning false cancels the render (like `cancel`).
    std::function<bool(const Progress&)> on_progress;
    /// Set to true (from any thread, or a signal handler) to stop: checked before every tile.
    const std::atomic<bool>* cancel = nullptr;
    /// Share the tiles out among this MPI job's ranks (null: this process alone): on rank 0 the
    /// result is the whole image, with every rank's rays; on the others, only the tiles that rank
    /// rendered. Render layers are refused: they are not sent between ranks.
    MpiJob* mpi_job = nullptr;
};

struct RenderStats {
    uint64_t camera_rays = 0, shadow_rays = 0, reflected_rays = 0;
    double seconds = 0;  ///< the render alone, without building the BVH
};

struct RenderResult {
    Image image;  ///< with cancelled, the finished tiles only (the others black)
    RenderStats stats;
    bool cancelled = false;
};

/// Checks the options against the scene without rendering, as render() does first: the layers'
/// names, that the scene can have them (not with a glazed, fresnel_ior, material yet) and that
/// the crop window lies inside the image.
WHITTED_API Expected<void> check_render_options(const Scene& scene, const RenderOptions& options = {});

/// The BVH as built for the scene.
struct AcceleratorInfo {
    size_t bytes = 0;       ///< Embree's memory for it
    size_t peak_bytes = 0;  ///< Embree's memory at most while building it
    std::string isa;        ///< Embree's instruction set as asked ($WHITTED_EMBREE_ISA); empty: Embree's choice
    int lane_width = 1;     ///< rays per packet given to Embree
    /// False for a scene of at most 16 spheres, boxes and cones and nothing else but planes,
    /// on few rays (shapes × camera rays × (1 + lights) ≤ 2²¹): each ray tests them all, with
    /// the same answers, and Embree is not loaded for it.
    bool has_bvh = true;
};

/// Builds the scene's BVH now with `threads` build threads (0 = all cores), as the first render
/// would (a Scene keeps it), and describes it.
WHITTED_API Expected<AcceleratorInfo> prepare(const Scene& scene, int threads = 0);

/// Renders the scene. Cancelling is not an error: the result says cancelled.
WHITTED_API Expected<RenderResult> render(const Scene& scene, const RenderOptions& options = {});
/// Renders the beauty into the caller's buffer: `floats` must be width·height·3 (R G B per
/// pixel, rows from the top; the crop window's width and height with a crop). A cancelled
/// render returns an Error of kind cancelled (the buffer then holds the finished tiles). Layers
/// are not available this way.
WHITTED_API Expected<RenderStats> render_into(const Scene& scene, float* rgb, size_t floats,
                                              const RenderOptions& options = {});

/// How write_image writes: the options of `whitted render` of the same names.
struct WriteOptions {
    bool half = false;            ///< EXR: half floats instead of 32-bit floats
    std::string exr_compression;  ///< EXR: none (default), zip, zips, piz, rle
    int bit_depth = 0;            ///< PNG/TIFF: 8 or 16; 0 = the format's default
    std::string ocio_config;      ///< PNG/JPEG/TIFF: empty = $OCIO, else the built-in config
    std::string display, view;    ///< PNG/JPEG/TIFF: empty = the config's defaults
    std::vector<std::pair<std::string, std::string>> metadata;  ///< extra string attributes
};

/// Writes the image as `whitted render` does: .exr linear (with its layers); .png/.jpg/.tif
/// through the display transform (the built-in config's; a config file's loads OpenColorIO). The
/// file appears complete or not at all.
WHITTED_API Expected<void> write_image(const Image& image, const std::string& path, const WriteOptions& options = {});

/// Checks, before any work, that write_image can write `path` with `options`, as `whitted
/// render` does first: an image extension it writes, every option applying to that format, the
/// `layers` (names as RenderOptions::layers) known and the format able to hold them (named as
/// asked for by `layers_from`, e.g. "--layers"), no symbolic link at `path` (writing replaces
/// it, it would not write through it), and not the file `input` (a scene file, by any name).
WHITTED_API Expected<void> check_image_output(const std::string& path, const WriteOptions& options,
                                              const std::vector<std::string>& layers = {},
                                              const std::string& layers_from = {}, const std::string& input = {});

/// The render layers' names RenderOptions::layers takes (besides "all" and "none"), comma-separated.
WHITTED_API std::string layer_choices();

/// The largest values a scene may hold (docs/scene-format.md), as its readers check them.
namespace limits {
inline constexpr int max_image_side = 65536;
inline constexpr int max_samples = 16;  ///< 256 rays per pixel
inline constexpr int max_depth = 256;
inline constexpr int64_t max_scene_file_bytes = int64_t(256) << 20;
}  // namespace limits

/// What Embree, which finds the hits, can do on this CPU (`whitted --version`).
struct EmbreeInfo {
    std::string version;                ///< e.g. "3.13.5"
    std::vector<std::string> isas;      ///< the instruction sets this CPU can run, narrowest first
    std::string isa_in_use;             ///< $WHITTED_EMBREE_ISA, else the widest of `isas`
    bool isa_from_environment = false;  ///< $WHITTED_EMBREE_ISA chose it
    int lane_width = 1;                 ///< rays per packet given to Embree with it
};
WHITTED_API Expected<EmbreeInfo> embree_info();
/// $WHITTED_EMBREE_ISA, checked before any work: a name Embree does not know, or an instruction
/// set this CPU lacks, is an Error (bad_input). The image is the same for every one.
WHITTED_API Expected<void> check_embree_isa();
/// Whether the large arrays the library maps for Embree (each triangle's widened corners and
/// their indices) ask for transparent huge pages (MADV_HUGEPAGE, faulted 2 MiB at a time)
/// instead of being mapped in whole as they are made (MAP_POPULATE). Off unless turned on; the
/// `whitted` program turns it on where a 4 KiB page's first write is dear (docs/performance.md,
/// "Huge pages where they pay"). Memory only: the image is the same bit for bit either way.
WHITTED_API void use_huge_pages(bool on);

/// `text` (a file name or word the user typed) made safe to print in a message: control
/// characters and bytes that are not UTF-8 as \xNN, at most `max_characters` characters.
WHITTED_API std::string printable(const std::string& text, size_t max_characters = 60);
/// " (did you mean 'x'?)" for the closest of `candidates` within a small edit distance, else "".
WHITTED_API std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);

/// How explain() writes the pixel's equation.
enum class ExplainFormat {
    text,     ///< every sample, segment, light and term with its numbers (`whitted explain`)
    summary,  ///< a dozen lines: the first hit, each term averaged over the samples, the pixel (`--summary`)
    json,     ///< docs/explain.schema.json (`--json`)
};

struct ExplainOptions {
    ExplainFormat format = ExplainFormat::json;
    int threads = 0;  ///< build threads for the BVH, if no render has built it yet (0 = all cores)
};

/// `whitted explain SCENE --pixel X,Y`: every term of pixel (x, y)'s equation (column, row from
/// the top-left, 0-based), traced as the render traces it (the same camera ray packets, so the
/// same numbers bit for bit), as the text `whitted explain` prints: ending in a newline, the scene
/// named by its path(). A pixel outside the image is an Error (bad_input).
WHITTED_API Expected<std::string> explain(const Scene& scene, int x, int y, const ExplainOptions& options = {});

/// The scene as POV-Ray 3.7 SDL (docs/pov-model.md), as `whitted convert s.yaml s.pov` writes it:
/// the description it was loaded from (or built with), whatever its file says now.
WHITTED_API Expected<std::string> to_povray(const Scene& scene);
/// Writes `pov_path` and the .ini beside it that renders it like Whitted; returns the .ini path.
WHITTED_API Expected<std::string> write_povray(const Scene& scene, const std::string& pov_path);

/// Checks, before any work, that convert() can write `output`, as `whitted convert` does first:
/// a format its extension names (.pov with the .ini beside it, .yaml/.yml), files that can be
/// written there, no symbolic link, and not the file `input` (the scene file, by any name).
WHITTED_API Expected<void> check_convert_output(const std::string& output, const std::string& input = {});
/// `whitted convert`: writes the scene in the format `output`'s extension names: .pov (POV-Ray
/// 3.7 SDL and the .ini beside it, as write_povray) or .yaml/.yml (Whitted's own format, as the
/// description said it). The description it was loaded from (SceneUse::any) is written, whatever
/// its file says now; an output that is one of the files it was read from is refused (bad_input)
/// before a byte is written. Returns the files written.
WHITTED_API Expected<std::vector<std::string>> convert(const Scene& scene, const std::string& output);

/// How `whitted check` runs (its options of the same names).
struct CheckOptions {
    int threads = 0;
    double tolerance_codes = 2;   ///< per channel, in 16-bit codes (1/65535)
    double min_fraction = 0.999;  ///< share of pixels within tolerance
    double max_error_codes = 64;  ///< hard cap, 16-bit codes
    std::string report_dir;       ///< empty: no report
    bool quiet = true;            ///< false: print the figures as `whitted check` does
    /// Render layers (docs/layers.md), as `check --layers`: Whitted renders with them, and its
    /// beauty, then the float sum of the colour layers, is compared. Empty: none.
    std::vector<std::string> layers;
    /// `check --terms`: the scene with only ambient, only diffuse, only specular, and each light
    /// alone (several lights), each checked against POV-Ray (a report per term in
    /// report_dir/TERM); the result passes when every term does, and its verdict names the terms
    /// that disagree.
    bool terms = false;
    /// `check --povray-image`: compare with this stored POV-Ray 16-bit PNG of the converted scene
    /// (samples·W × samples·H) instead of running POV-Ray; empty: run POV-Ray.
    std::string povray_image;
    double exposure = 1;  ///< with povray_image: the exposure it was made at (a power of two ≤ 1)
    /// Set to true (from any thread, or a signal handler) to stop: POV-Ray is ended, the
    /// temporary files are removed, and check() returns an Error of kind cancelled.
    const std::atomic<bool>* cancel = nullptr;
    /// When given, check() sets it to false before it creates its first file or directory: while
    /// it is true a signal handler may end the process at once, as there is nothing to clean up.
    std::atomic<bool>* nothing_created_yet = nullptr;
};

/// What check() found.
struct CheckResult {
    bool passed = false;
    double fraction_within = 0;  ///< share of pixels within tolerance
    double max_error_codes = 0;  ///< largest error of any channel, 16-bit codes
    double psnr = 0;             ///< dB
    std::vector<std::string> failures;
    std::string verdict;  ///< the verdict line `whitted check` prints last
};

/// `whitted check`: renders the scene file with Whitted and, converted, with POV-Ray 3.7 (found
/// as $WHITTED_POVRAY or `povray`) and compares them pixel by pixel (docs/validation.md). Loads
/// the OpenImageIO plug-in. Prints the verdict line (and, unless quiet, the figures) on standard
/// output, as `whitted check` does. A failed comparison is a result, not an Error; a cancelled
/// check is an Error of kind cancelled.
WHITTED_API Expected<CheckResult> check(const std::string& scene_path, const CheckOptions& options = {});

/// The pass rule of `whitted compare` and `whitted check` (docs/validation.md), in 16-bit codes
/// (1/65535 of the linear range): at least `min_fraction` of the pixels have every channel within
/// `tolerance_codes`, no channel of any pixel is off by more than `max_error_codes`, no value of
/// either image is NaN or ±Inf, and both images have the same size and channel count.
struct PassRule {
    double tolerance_codes = 2;
    double min_fraction = 0.999;
    double max_error_codes = 64;
};

/// What compare_image_files() found.
struct Comparison {
    bool passed = false;
    /// What each file was read as ("linear Rec.709 (EXR)", "sRGB display codes ..."); empty
    /// when the images could not be compared at all (their sizes or channels differ).
    std::string first_meaning, second_meaning;
    double fraction_within = 0;         ///< share of pixels within tolerance
    double max_error_codes = 0;         ///< largest error of any channel, 16-bit codes (infinity with NaN/Inf)
    double rms_error = 0;               ///< linear units
    std::vector<std::string> failures;  ///< the rules broken, e.g. "cap (max 1000.0 codes > 64)"
    std::string verdict;                ///< "PASS A vs B: ..." or "FAIL A vs B: ...", as `whitted compare` prints
};

/// `whitted compare A B`: the two image files (EXR, PNG, JPEG, TIFF, ...), each first turned into
/// linear Rec.709 from its colour metadata, compared channel by channel under `rule`. With
/// `clip`, both are clipped to [0, 1] first (a float EXR against a PNG, which clips); NaN and Inf
/// values are counted before that. Loads the OpenImageIO plug-in. Images that differ are a
/// result, not an Error; a file that cannot be read or whose colour is not known is an Error
/// (bad_input).
WHITTED_API Expected<Comparison> compare_image_files(const std::string& first, const std::string& second,
                                                     const PassRule& rule = {}, bool clip = false);

/// `whitted colour --list`: each display and view of the OpenColorIO config at `config_path`
/// (empty: $OCIO, else the built-in config), the colour space it writes and what that means; the
/// text `whitted colour --list` prints.
WHITTED_API Expected<std::string> describe_colour_config(const std::string& config_path = {});

/// `whitted colour --write-config`: writes the built-in OpenColorIO config (the one write_image
/// uses without $OCIO) to `path`, for other programs (oiiotool, Nuke, Blender). The file appears
/// complete or not at all; a symbolic link is not written through.
WHITTED_API Expected<void> write_colour_config(const std::string& path);

}  // namespace whitted::api
