// SPDX-License-Identifier: MIT
#pragma once

#include "compare.h"
#include "scene/description.h"
#include "scene/layer_names.h"

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

namespace whitted::reference {

/// Thrown when a check is cancelled (a signal): POV-Ray has been stopped, and the temporary
/// directories go with the unwinding.
struct Interrupted : std::runtime_error {
    Interrupted() : std::runtime_error("interrupted") {}
};

/// Everything one run of the check needs: api::CheckOptions (which the API turns into this) in
/// the comparison's own units, plus what only the `whitted` program and the report use.
struct CheckRun {
    std::string report_dir;  ///< empty: no report
    PassRule rule;
    size_t worst_count = 10;  ///< pixels listed by the report
    int threads = 0;
    bool quiet = false;
    /// Whitted renders with these render layers (docs/layers.md); its beauty, then the float
    /// sum of the colour layers, is what is compared.
    LayerSet layers;
    /// Check term by term (`check --terms`): see run_check_terms.
    bool terms = false;
    /// When set, POV-Ray is not run: this stored POV-Ray image (its linear 16-bit PNG of the
    /// converted scene, n·W × n·H for image.samples n) is compared instead, at `exposure`, the
    /// exposure it was rendered with (`whitted check` prints and reports it). The image tier
    /// uses this to check against POV-Ray without POV-Ray installed (tests/image/README.md).
    std::string povray_image;
    double exposure = 1;  ///< only with povray_image
    /// Set (by a signal handler) to stop: POV-Ray is ended and run_check throws Interrupted.
    const std::atomic<bool>* cancel = nullptr;
    /// While true a signal may end the program at once, since nothing exists to clean up yet;
    /// run_check sets it to false before it creates its first directory or file.
    std::atomic<bool>* exit_at_once = nullptr;
};

/// Everything one run of the check found, for the table, the report and the verdict line;
/// api::CheckResult is the part a caller of the library is given.
struct CheckRecord {
    ImageComparison comparison;
    double exposure = 1;  ///< the scale both images were compared at (< 1 for scenes brighter than 1)
    bool passed = false;
    std::vector<std::string> failures;  ///< the rules broken (failed_rules, shape_mismatches)
    int samples = 1;                    ///< image.samples: POV-Ray rendered samples×W by samples×H
    double whitted_seconds = 0, povray_seconds = 0;
    int povray_runs = 0;                           ///< more than 1 when POV-Ray clipped and was run again darker
    std::string povray_program;                    ///< the povray that ran
    std::string pov_file, ini_file, povray_image;  ///< file names inside the work (report) directory
};

/// Renders the scene with Whitted and (converted) with POV-Ray, compares them, prints the
/// figures and writes the report. Throws InputError / std::runtime_error on errors.
CheckRecord run_check(const std::string& scene_path, const CheckRun& options);
/// The same for a description already read; `label` names it in messages and the report.
CheckRecord run_check(const SceneDescription& description, const std::string& label, const CheckRun& options);

/// One term-isolated variant of a scene (`check --terms`).
struct TermScene {
    std::string term;  ///< "ambient", "diffuse", "specular", "light 1", ...
    SceneDescription description;
};
/// The scene with only one term of the equation left, for each term the scene has: ambient
/// (kd = ks = km = 0), diffuse (ka = ks = km = 0), specular (ka = kd = km = 0), and, with
/// several lights, each light alone with ka = km = 0. A term no material has (every ks 0, say)
/// is left out. Throws InputError for a mesh whose materials come from its MTL file (they are
/// not in the description to change).
std::vector<TermScene> term_scenes(const SceneDescription& description);
/// `check --terms`: run_check on every term_scenes variant (reports in report_dir/<term>),
/// then one line naming the terms that failed, printed and returned; `failed` gets their names.
std::string run_check_terms(const std::string& scene_path, const CheckRun& options, std::vector<std::string>& failed);

/// Writes ours.png, povray.png, diff.png (scaled heat map), ours.exr, povray.exr (both losslessly
/// compressed), report-data.js, metrics.json and report.html into `dir`. `ours` and `theirs` are the images as
/// compared, i.e. already multiplied by result.exposure; the EXRs are written at the scene's own scale (ours.exr is
/// what `whitted render` writes), the PNGs and the heat map at the compared scale.
void write_report(const std::string& dir, const std::string& scene_path, const Image& ours, const Image& theirs,
                  const CheckRecord& result, const CheckRun& options);

/// The one-line verdict printed last by `whitted check` (scripts/validate reads it), e.g.
/// "PASS scene.yaml: 100.000% of pixels within 2/65535 (99.9% required), max 1.0 codes (cap 64)",
/// or with "; failed: cap (max 1000.0 codes > 64)" and the like for each rule broken.
std::string verdict_line(const std::string& scene_path, const CheckRecord& result, const CheckRun& options);

}  // namespace whitted::reference
