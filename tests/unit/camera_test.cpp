// SPDX-License-Identifier: MIT
// Primary rays against scene-format v1 §"Primary rays": pixel (i, j) → x0 = (i + 0.5)/W − 0.5,
// y0 = 0.5 − (j + 0.5)/H; horizontal fov; right-handed (looking down −z with up +y, screen-right
// is +x). Expected directions are built here from those formulas, not from the camera code.

#include "render/camera.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace whitted {
namespace {

constexpr double tolerance = 1e-12;

double degrees_to_radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}

CameraDescription perspective(const Vec3& eye, const Vec3& look_at, const Vec3& up, double fov) {
    CameraDescription d;
    d.type = CameraType::perspective;
    d.eye = eye;
    d.look_at = look_at;
    d.up = up;
    d.fov = fov;
    return d;
}

CameraDescription orthographic(const Vec3& eye, const Vec3& look_at, const Vec3& up, double view_width) {
    CameraDescription d;
    d.type = CameraType::orthographic;
    d.eye = eye;
    d.look_at = look_at;
    d.up = up;
    d.view_width = view_width;
    return d;
}

double pixel_x0(int i, int width) {
    return (i + 0.5) / width - 0.5;
}
double pixel_y0(int j, int height) {
    return 0.5 - (j + 0.5) / height;
}

void expect_vec_near(const Vec3& actual, const Vec3& expected, double tol, const std::string& what) {
    EXPECT_NEAR(actual.x, expected.x, tol) << what;
    EXPECT_NEAR(actual.y, expected.y, tol) << what;
    EXPECT_NEAR(actual.z, expected.z, tol) << what;
}

// Every pixel of a non-square image, camera at the origin looking down −z: the direction
// through (x0, y0) is (2·x0·tan(fov/2), 2·y0·tan(fov/2)·H/W, −1), normalised, because the
// horizontal half-extent at unit distance is tan(fov/2) and pixels are square.
TEST(Camera, PerspectiveRaysThroughEveryPixelCentreOfNonSquareImage) {
    for (const auto& [width, height, fov] : {std::tuple{4, 2, 90.0}, std::tuple{7, 3, 60.0}, std::tuple{3, 8, 30.0}}) {
        const Camera camera = make_camera(perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, fov), width, height);
        const double half_extent = std::tan(degrees_to_radians(fov) / 2);
        for (int j = 0; j < height; ++j) {
            for (int i = 0; i < width; ++i) {
                const double x0 = pixel_x0(i, width), y0 = pixel_y0(j, height);
                const Ray ray = camera_ray(camera, x0, y0);
                const Vec3 expected = normalize({2 * x0 * half_extent, 2 * y0 * half_extent * height / width, -1.0});
                const std::string what = "pixel (" + std::to_string(i) + ", " + std::to_string(j) + ") of " +
                                         std::to_string(width) + "x" + std::to_string(height);
                expect_vec_near(ray.direction, expected, tolerance, what);
                expect_vec_near(ray.origin, {0, 0, 0}, 0.0, what);
            }
        }
    }
}

// Right-handed: with eye looking down −z and up +y, the rightmost column points to +x and the
// top row to +y (a left-handed camera would flip x).
TEST(Camera, ScreenRightIsPlusXLookingDownMinusZ) {
    const Camera camera = make_camera(perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 45), 10, 10);
    const Ray top_right = camera_ray(camera, pixel_x0(9, 10), pixel_y0(0, 10));
    const Ray bottom_left = camera_ray(camera, pixel_x0(0, 10), pixel_y0(9, 10));
    EXPECT_GT(top_right.direction.x, 0);
    EXPECT_GT(top_right.direction.y, 0);
    EXPECT_LT(bottom_left.direction.x, 0);
    EXPECT_LT(bottom_left.direction.y, 0);
    EXPECT_LT(top_right.direction.z, 0);
}

// The fov is horizontal: the left/right image edges are fov/2 off the view axis, the top edge
// atan(tan(fov/2)·H/W).
TEST(Camera, FovIsHorizontalAndVerticalFollowsAspect) {
    const double fov = 50;
    const int width = 16, height = 9;
    const Camera camera = make_camera(perspective({1, 2, 3}, {1, 2, -7}, {0, 1, 0}, fov), width, height);
    const Vec3 forward{0, 0, -1};
    const double right_edge = std::acos(dot(camera_ray(camera, 0.5, 0).direction, forward));
    const double left_edge = std::acos(dot(camera_ray(camera, -0.5, 0).direction, forward));
    const double top_edge = std::acos(dot(camera_ray(camera, 0, 0.5).direction, forward));
    EXPECT_NEAR(right_edge, degrees_to_radians(fov / 2), 1e-12);
    EXPECT_NEAR(left_edge, degrees_to_radians(fov / 2), 1e-12);
    EXPECT_NEAR(top_edge, std::atan(std::tan(degrees_to_radians(fov / 2)) * height / width), 1e-12);
}

// The centre of an odd-sized image looks exactly at look_at, from eye, whatever the orientation.
TEST(Camera, CentrePixelLooksAtTarget) {
    const Vec3 eye{1, 2, 3}, look_at{4, 6, 3};
    const Camera camera = make_camera(perspective(eye, look_at, {0, 0, 1}, 70), 5, 3);
    const Ray ray = camera_ray(camera, pixel_x0(2, 5), pixel_y0(1, 3));
    expect_vec_near(ray.origin, eye, 0.0, "origin");
    expect_vec_near(ray.direction, {0.6, 0.8, 0}, tolerance, "direction");
}

// Looking down +x with up +y, screen-right is forward × up = +z (right-handed), so the ray through
// (x0, y0) is ∝ (1, 0, 0) + 2·x0·tan(fov/2)·(0, 0, 1) + 2·y0·tan(fov/2)·(H/W)·(0, 1, 0).
TEST(Camera, TurnedCameraKeepsRightHandedBasis) {
    const double fov = 80;
    const int width = 6, height = 4;
    const Camera camera = make_camera(perspective({0, 0, 0}, {5, 0, 0}, {0, 1, 0}, fov), width, height);
    const double half_extent = std::tan(degrees_to_radians(fov) / 2);
    const double x0 = pixel_x0(5, width), y0 = pixel_y0(3, height);
    const Vec3 expected = normalize(Vec3{1, 0, 0} + Vec3{0, 0, 1} * (2 * x0 * half_extent) +
                                    Vec3{0, 1, 0} * (2 * y0 * half_extent * height / width));
    expect_vec_near(camera_ray(camera, x0, y0).direction, expected, tolerance, "pixel (5, 3)");
    EXPECT_GT(expected.z, 0);  // the rightmost column really is on the +z side
}

// `up` need not be orthogonal to the view: only its part orthogonal to the view matters.
TEST(Camera, UpNeedNotBeOrthogonalToView) {
    const Camera straight = make_camera(perspective({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 45), 8, 5);
    const Camera tilted = make_camera(perspective({0, 0, 0}, {0, 0, -1}, {0, 3, 2}, 45), 8, 5);
    for (const auto& [x0, y0] : {std::pair{0.3, -0.2}, std::pair{-0.45, 0.4}}) {
        expect_vec_near(camera_ray(tilted, x0, y0).direction, camera_ray(straight, x0, y0).direction, tolerance,
                        "tilted up");
    }
}

// Orthographic: every ray is parallel to the view, starting on the image plane through eye at
// eye + x0·view_width·right + y0·(view_width·H/W)·up.
TEST(Camera, OrthographicRaysAreParallelAndSpanViewWidth) {
    const double view_width = 4;
    const int width = 8, height = 4;
    const Camera camera = make_camera(orthographic({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, view_width), width, height);
    for (int j = 0; j < height; ++j) {
        for (int i = 0; i < width; ++i) {
            const double x0 = pixel_x0(i, width), y0 = pixel_y0(j, height);
            const Ray ray = camera_ray(camera, x0, y0);
            const std::string what = "pixel (" + std::to_string(i) + ", " + std::to_string(j) + ")";
            expect_vec_near(ray.direction, {0, 0, -1}, tolerance, what);
            expect_vec_near(ray.origin, {x0 * view_width, y0 * view_width * height / width, 10}, tolerance, what);
        }
    }
    // The first column's centre is half a pixel in from the left edge at −view_width/2.
    EXPECT_NEAR(camera_ray(camera, pixel_x0(0, width), 0).origin.x, -view_width / 2 + view_width / width / 2,
                tolerance);
}

// Orthographic looking down −x with up +z: screen-right is forward × up = (−1,0,0) × (0,0,1) = +y.
TEST(Camera, OrthographicTurnedCamera) {
    const int width = 5, height = 10;
    const Camera camera = make_camera(orthographic({7, 1, 2}, {0, 1, 2}, {0, 0, 1}, 2.5), width, height);
    const double x0 = pixel_x0(4, width), y0 = pixel_y0(0, height);
    const Ray ray = camera_ray(camera, x0, y0);
    expect_vec_near(ray.direction, {-1, 0, 0}, tolerance, "direction");
    expect_vec_near(ray.origin, {7, 1 + x0 * 2.5, 2 + y0 * 2.5 * height / width}, tolerance, "origin");
}

// Supersampling: the n×n sample grid of a pixel is centred on that pixel's centre and stays inside it.
TEST(Camera, SampleGridIsCentredInsideThePixel) {
    const int width = 7, height = 5, n = 3, i = 4, j = 2;
    double sum_x = 0, sum_y = 0;
    for (int b = 0; b < n; ++b) {
        for (int a = 0; a < n; ++a) {
            double x0, y0;
            sample_position(i, j, a, b, n, width, height, x0, y0);
            EXPECT_GT(x0, double(i) / width - 0.5);
            EXPECT_LT(x0, double(i + 1) / width - 0.5);
            EXPECT_LT(y0, 0.5 - double(j) / height);
            EXPECT_GT(y0, 0.5 - double(j + 1) / height);
            sum_x += x0, sum_y += y0;
        }
    }
    EXPECT_NEAR(sum_x / (n * n), pixel_x0(i, width), 1e-15);
    EXPECT_NEAR(sum_y / (n * n), pixel_y0(j, height), 1e-15);
}

}  // namespace
}  // namespace whitted
