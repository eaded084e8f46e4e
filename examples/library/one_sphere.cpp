// SPDX-License-Identifier: MIT
// Whitted as a library (docs/library.md): a scene built in code, rendered, written, and one pixel
// checked against the lecture's formula by hand.
//   one_sphere [OUT.exr]   exits 0 when the pixel is right, 1 when it is not, 2 on an error.
#include <whitted/whitted.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
    namespace api = whitted::api;
    std::printf("Whitted library %s (headers %s)\n", api::version(), WHITTED_VERSION_STRING);

    // One diffuse sphere at the origin, a point light at the eye: the ray through the centre
    // pixel of the (odd-sized) image meets the sphere at (0, 0, 1), where n = l = (0, 0, 1).
    const api::Vec3 ka{0.2, 0.1, 0.05}, kd{0.5, 0.25, 0.125}, ia{0.5, 0.5, 0.5}, light{0.8, 0.8, 0.8};
    api::Material material;
    material.ka = ka;
    material.kd = kd;
    api::Expected<api::Scene> scene = api::SceneBuilder()
                                          .image(65, 65)
                                          .background({0.25, 0.5, 0.75})
                                          .camera({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 30)
                                          .ambient(ia)
                                          .point_light({0, 0, 5}, light)
                                          .sphere({0, 0, 0}, 1, material)
                                          .build();
    if (!scene) {
        std::fprintf(stderr, "one_sphere: %s\n", scene.error().what().c_str());
        return 2;
    }

    api::RenderOptions options;
    options.threads = 2;
    api::Expected<api::RenderResult> result = api::render(*scene, options);
    if (!result) {
        std::fprintf(stderr, "one_sphere: %s\n", result.error().what().c_str());
        return 2;
    }
    const whitted::Image& image = result->image;
    if (argc > 1) {
        if (auto written = api::write_image(image, argv[1]); !written) {
            std::fprintf(stderr, "one_sphere: %s\n", written.error().what().c_str());
            return 2;
        }
    }

    // L = ka·Ia + kd·I·max(0, n·l) with n·l = 1 (no specular, no mirror); the corner misses: background.
    const double want[3] = {ka.x * ia.x + kd.x * light.x, ka.y * ia.y + kd.y * light.y, ka.z * ia.z + kd.z * light.z};
    const double background[3] = {0.25, 0.5, 0.75};
    const float* centre = image.pixel(32, 32);
    const float* corner = image.pixel(0, 0);
    bool ok = true;
    for (int c = 0; c < 3; ++c) {
        ok = ok && std::fabs(centre[c] - want[c]) < 1e-6 && corner[c] == float(background[c]);
    }
    // The same beauty into a buffer of the caller's; a wrong size is an error, not a crash.
    std::vector<float> buffer(size_t(image.width) * size_t(image.height) * 3);
    const api::Expected<api::RenderStats> into = api::render_into(*scene, buffer.data(), buffer.size(), options);
    const bool same = into && buffer == image.rgb;
    const bool refused = !api::render_into(*scene, buffer.data(), buffer.size() - 1, options);
    // Cancelled before the first tile: no pixel rendered.
    std::atomic<bool> stop{true};
    api::RenderOptions cancelled = options;
    cancelled.cancel = &stop;
    const api::Expected<api::RenderResult> stopped = api::render(*scene, cancelled);
    const bool cancel_ok = stopped && stopped->cancelled && stopped->stats.camera_rays == 0;
    std::printf("render_into: %s; wrong size refused: %s; cancel: %s\n", same ? "same pixels" : "DIFFERENT",
                refused ? "yes" : "NO", cancel_ok ? "ok" : "WRONG");
    ok = ok && same && refused && cancel_ok;

    std::printf("centre pixel %.7f %.7f %.7f (lecture formula %.7f %.7f %.7f); corner %.7f %.7f %.7f: %s\n", centre[0],
                centre[1], centre[2], want[0], want[1], want[2], corner[0], corner[1], corner[2], ok ? "ok" : "WRONG");
    return ok ? 0 : 1;
}
