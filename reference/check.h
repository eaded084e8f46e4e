// SPDX-License-Identifier: MIT
#pragma once

#include "compare.h"

#include <string>

namespace whitted::reference {

struct CheckOptions {
    std::string report_dir;            ///< empty: no report
    double tolerance = 2.0 / 65535.0;  ///< per channel, absolute, linear
    double required_fraction = 0.999;  ///< share of pixels that must be within tolerance
    int threads = 0;
    bool quiet = false;
};

struct CheckResult {
    ImageComparison comparison;
    double exposure = 1;  ///< the scale both images were compared at (< 1 for scenes brighter than 1)
    bool passed = false;
};

/// Renders the scene with Whitted and (converted) with POV-Ray, compares them, prints the
/// figures and writes the report. Throws InputError / std::runtime_error on errors.
CheckResult run_check(const std::string& scene_path, const CheckOptions& options);

/// Writes ours.png, povray.png, diff.png (scaled heat map), ours.exr, povray.exr, metrics.json
/// and report.html into `dir`.
void write_report(const std::string& dir, const std::string& scene_path, const Image& ours, const Image& theirs,
                  const CheckResult& result, const CheckOptions& options);

}  // namespace whitted::reference
