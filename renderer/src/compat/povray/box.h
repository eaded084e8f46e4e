// SPDX-License-Identifier: MIT
#pragma once

// POV-Ray 3.7's box test (its boxes.cpp; facts only, the code is Whitted's own), for
// `render.intersection: povray`: POV-Ray's tolerances in t, and the face it reports near an
// edge (docs/pov-model.md §3, "Box edges"), so that both renderers shade an edge pixel with the
// same normal. The exact slab test is geometry/shapes.h's intersect_box.

#include "geometry/shapes.h"

namespace whitted {

/// intersect_box with POV-Ray's constants and edge rule: when a later axis's crossing is within
/// 1e-6 (in t) of the crossing found so far, that axis's face takes over if the ray runs more
/// steeply along it (for y weighed against x; for z against the axis of the face held so far),
/// and the hit says so (ShapeHit::edge_tie).
bool intersect_box_as_povray(const Box& box, const Ray& ray, double t_min, double t_max, ShapeHit& hit);

}  // namespace whitted
