// SPDX-License-Identifier: MIT
#pragma once

// POV-Ray 3.7's own decisions, where they differ from the exact answer, in one place. Whitted's
// renders decide hits exactly (`render.intersection: exact`, the default); `whitted check`
// renders with `render.intersection: povray`, which takes these instead, so that the two
// renderers agree pixel by pixel (docs/scene-format.md §5.2 lists both rule sets). The
// converter (converters/pov_writer.cpp) uses them to know how POV-Ray will hold what it writes.
//
// * box.h: the box test with its tolerances and the face it reports near an edge;
// * mesh2.h: the single-precision mesh2 triangle test (on a mesh's triangle as the converter
//   writes it), its smooth normal, and the vertex normals as POV-Ray stores them;
// * tie_order.h: the order in which POV-Ray tests spheres and boxes (its bounding slabs and
//   priority queue), which settles exact ties, and the box edge rule's part in a tie.
//
// Two more live where the rule is chosen, as a switch on Scene::intersection: the distances
// that keep a ray off its surface and the far limit (render/ray_spans.h, from core/ray.h's
// ray_limits), and a plane keeping a tie within an ulp (the accelerator's finish_hit).

#include "compat/povray/box.h"
#include "compat/povray/mesh2.h"
#include "compat/povray/tie_order.h"
