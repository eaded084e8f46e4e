// SPDX-License-Identifier: MIT
// api::explain (whitted/whitted.h): one pixel's equation as `whitted explain` prints it, term by
// term as text, in a dozen lines, or as JSON (docs/explain.schema.json).

#include "render/explain.h"
#include "api_internal.h"
#include "scene/errors.h"
#include "scene/source_location.h"
#include "scene/text_checks.h"

#include <fmt/format.h>
#include <fmt/printf.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace whitted {

namespace {

/// printf's format, appended to `out`.
template <class... Args>
void say(std::string& out, const char* format, const Args&... args) {
    out += fmt::sprintf(format, args...);
}

std::string vec(const Vec3& v) {
    return fmt::format("({}, {}, {})", v.x, v.y, v.z);
}
nlohmann::json jvec(const Vec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}
nlohmann::json jray(const Ray& r) {
    return {{"origin", jvec(r.origin)}, {"direction", jvec(r.direction)}, {"t_min", r.t_min}, {"t_max", r.t_max}};
}

std::string object_label(const Scene& scene, uint32_t object) {
    if (object == 0 || object > scene.objects.size()) return fmt::format("object {}", object);
    const SceneObject& o = scene.objects[object - 1];
    return fmt::format("object {} ({}, {})", object, to_string(o.type), printable(o.where.str(), 4096));
}
nlohmann::json jobject(const Scene& scene, uint32_t object) {
    nlohmann::json j = {{"id", object}};
    if (object >= 1 && object <= scene.objects.size()) {
        j["type"] = to_string(scene.objects[object - 1].type);
        j["where"] = scene.objects[object - 1].where.str();
    }
    return j;
}
std::string material_label(const Scene& scene, uint32_t material) {
    const std::string& name = scene.material_names[material];
    return fmt::format("material {} ({})", material + 1, name.empty() ? "inline" : "'" + printable(name) + "'");
}

/// The specular lobe's pieces for the printout: h and n·h (Blinn) or r_v and r_v·l (Phong).
struct Lobe {
    Vec3 vector;
    double cosine = 0, value = 0;
};
Lobe lobe_of(const Material& material, const Vec3& normal, const Vec3& to_eye, const Vec3& to_light) {
    Lobe lobe;
    if (material.highlight == Highlight::blinn) {
        const Vec3 h = to_eye + to_light;
        const double len = length(h);
        lobe.vector = len > 0 ? h / len : Vec3(0.0);
        lobe.cosine = len > 0 ? dot(h, normal) / len : 0.0;
    } else {
        lobe.vector = normal * (2.0 * dot(normal, to_eye)) - to_eye;
        lobe.cosine = dot(lobe.vector, to_light);
    }
    lobe.value = LectureShading::specular_lobe(material, normal, to_eye, to_light);
    return lobe;
}

std::string light_label(const Scene& scene, size_t index) {
    const Light& light = scene.lights[index];
    if (light.type == LightType::point)
        return fmt::format("light {} (point at {}, I = {})", index + 1, vec(light.position), vec(light.intensity));
    return fmt::format("light {} (directional, toward the light {}, I = {})", index + 1, vec(light.toward_light),
                       vec(light.intensity));
}

void write_text(std::string& out, const Scene& scene, const std::string& path, const PixelExplanation& e) {
    const int n = scene.samples;
    say(out, "pixel (%d, %d) of %s: %dx%d, %d sample(s) per pixel, max depth %d\n", e.x, e.y,
        printable(path, 4096).c_str(), scene.width, scene.height, n * n, scene.max_depth);
    say(out, "L = ka*Ia + sum_i [kd*I_i*max(0,n.l_i) + ks*I_i*max(0,n.h_i)^p] + km*L(r)\n");
    for (const ExplainedSample& sample : e.samples) {
        say(out, "\nsample %d (column %d, row %d of the %dx%d grid)\n", sample.sample, sample.sample % n,
            sample.sample / n, n, n);
        for (const ExplainedSegment& s : sample.segments) {
            say(out, "  segment %d: %s from %s along %s, t in (%s, %s), weight %s\n", s.level,
                s.level == 0       ? "camera ray"
                : s.refracted_path ? "refracted ray"
                                   : "mirror ray",
                vec(s.ray.origin).c_str(), vec(s.ray.direction).c_str(), fmt::format("{}", s.ray.t_min).c_str(),
                fmt::format("{}", s.ray.t_max).c_str(), vec(s.weight).c_str());
            if (!s.hit) {
                say(out, "    miss: weight*background = %s*%s = %s\n", vec(s.weight).c_str(),
                    vec(scene.background).c_str(), vec(s.seen).c_str());
                continue;
            }
            const Material& m = scene.materials[s.surface.material];
            const Vec3 v = -s.ray.direction;
            say(out, "    hit %s, %s, at t = %s\n", object_label(scene, s.surface.object).c_str(),
                material_label(scene, s.surface.material).c_str(), fmt::format("{}", s.surface.t).c_str());
            say(out, "    x = %s\n    n = %s (shading normal, turned toward the ray); Ng = %s\n    v = %s\n",
                vec(s.surface.point).c_str(), vec(s.normal).c_str(), vec(s.surface.geometric_normal).c_str(),
                vec(v).c_str());
            say(out, "    ambient  ka*Ia = %s*%s = %s\n", vec(m.ka).c_str(), vec(scene.ambient).c_str(),
                vec(s.ambient).c_str());
            for (const ExplainedLight& l : s.lights) {
                const LightTerms& t = l.terms;
                say(out, "    %s: l = %s, n.l = %s\n", light_label(scene, l.light).c_str(), vec(t.to_light).c_str(),
                    fmt::format("{}", t.n_dot_l).c_str());
                if (!t.facing) {
                    say(out, "      n.l <= 1e-10: the light is behind the surface (or at x); adds nothing\n");
                    continue;
                }
                const Lobe lobe = lobe_of(m, s.normal, v, t.to_light);
                if (m.highlight == Highlight::blinn)
                    say(out, "      h = %s, n.h = %s, max(0,n.h)^p = %s (p = %s)\n", vec(lobe.vector).c_str(),
                        fmt::format("{}", lobe.cosine).c_str(), fmt::format("{}", lobe.value).c_str(),
                        fmt::format("{}", m.p).c_str());
                else
                    say(out, "      Phong: r_v = 2(n.v)n - v = %s, r_v.l = %s, max(0,r_v.l)^p = %s (p = %s)\n",
                        vec(lobe.vector).c_str(), fmt::format("{}", lobe.cosine).c_str(),
                        fmt::format("{}", lobe.value).c_str(), fmt::format("{}", m.p).c_str());
                if (!t.shadow_tested) {
                    say(out, "      shadow ray: empty range (the light is within 1e-3 of x): not blocked\n");
                } else if (t.blocked) {
                    say(out, "      shadow ray from x along l, t in (%s, %s): blocked by %s%s; adds nothing\n",
                        fmt::format("{}", t.shadow_ray.t_min).c_str(), fmt::format("{}", t.shadow_ray.t_max).c_str(),
                        l.blocker ? object_label(scene, l.blocker->object).c_str() : "a surface",
                        l.blocker ? fmt::format(" at t = {}", l.blocker->t).c_str() : "");
                    continue;
                } else {
                    say(out, "      shadow ray from x along l, t in (%s, %s): clear\n",
                        fmt::format("{}", t.shadow_ray.t_min).c_str(), fmt::format("{}", t.shadow_ray.t_max).c_str());
                }
                // Through transmitting surfaces the light arrives as I times their kt (the filter).
                const Color intensity = scene.lights[l.light].intensity * t.filter;
                if (!(t.filter == Color(1.0)))
                    say(out, "      through transmitting surfaces: I*filter = %s*%s = %s\n",
                        vec(scene.lights[l.light].intensity).c_str(), vec(t.filter).c_str(), vec(intensity).c_str());
                say(out, "      diffuse   kd*I*(n.l) = %s*%s*%s = %s\n", vec(m.kd).c_str(), vec(intensity).c_str(),
                    fmt::format("{}", t.n_dot_l).c_str(), vec(t.diffuse).c_str());
                say(out, "      specular  ks*I*lobe = %s*%s*%s = %s\n", vec(m.ks).c_str(), vec(intensity).c_str(),
                    fmt::format("{}", lobe.value).c_str(), vec(t.specular).c_str());
            }
            say(out, "    local = ka*Ia + sum(diffuse + specular) = %s\n", vec(s.local).c_str());
            say(out, "    weight*local = %s*%s = %s\n", vec(s.weight).c_str(), vec(s.local).c_str(),
                vec(s.added).c_str());
            if (s.mirrored)
                say(out, "    mirror: km = %s, r = 2(n.v)n - v = %s; next weight = weight*km = %s\n", vec(m.km).c_str(),
                    vec(s.mirror_ray.direction).c_str(), vec(s.mirror_weight).c_str());
            else if (!is_zero(m.km))
                say(out, "    mirror: km = %s, but max depth %d is reached: L(r) = 0\n", vec(m.km).c_str(),
                    scene.max_depth);
            if (s.transmitted)
                say(out,
                    "    refracted: kt = %s, ior = %s, t = %s; its weight = weight*kt = %s (its segments come "
                    "next, then the mirror ray's)\n",
                    vec(m.kt).c_str(), fmt::format("{}", m.ior).c_str(), vec(s.refracted_ray.direction).c_str(),
                    vec(s.refracted_weight).c_str());
            else if (!is_zero(m.kt) && s.mirrored && s.mirror_weight == s.weight)
                say(out,
                    "    refracted: kt = %s, ior = %s: total internal reflection, the mirror ray carries "
                    "the light with weight 1\n",
                    vec(m.kt).c_str(), fmt::format("{}", m.ior).c_str());
        }
        say(out, "  L = sum of the weighted terms above, in order = %s\n", vec(sample.radiance).c_str());
    }
    say(out, "\npixel = sum(L) / %d = %s\n", n * n, vec(e.pixel).c_str());
    say(out, "as float (the R, G, B of `whitted render`'s EXR): %s\n",
        fmt::format("({}, {}, {})", e.rgb[0], e.rgb[1], e.rgb[2]).c_str());
    const PathLayers& c = e.layers.sum;
    say(out, "render layers: ambient %s + diffuse %s + specular %s + mirror %s + transmission %s + background %s\n",
        vec(c.ambient).c_str(), vec(c.diffuse).c_str(), vec(c.specular).c_str(), vec(c.mirror).c_str(),
        vec(c.transmission).c_str(), vec(c.background).c_str());
    say(out, "  = %s as the float sum (the R, G, B of an EXR rendered with --layers)\n",
        fmt::format("({}, {}, {})", e.layer_beauty[0], e.layer_beauty[1], e.layer_beauty[2]).c_str());
}

/// The pixel in a dozen lines: what the first sample's camera ray hit, each of the lecture's
/// terms averaged over the samples (the render layers of the pixel), and the pixel itself.
void write_summary(std::string& out, const Scene& scene, const std::string& path, const PixelExplanation& e) {
    const int n = scene.samples;
    say(out, "pixel (%d, %d) of %s: %dx%d, %d sample(s) per pixel, max depth %d\n", e.x, e.y,
        printable(path, 4096).c_str(), scene.width, scene.height, n * n, scene.max_depth);
    const ExplainedSegment& first = e.samples.front().segments.front();
    if (first.hit)
        say(out, "  first hit (sample 0): %s, %s, at t = %s\n", object_label(scene, first.surface.object).c_str(),
            material_label(scene, first.surface.material).c_str(), fmt::format("{}", first.surface.t).c_str());
    else
        say(out, "  first hit (sample 0): none, the background\n");
    const PathLayers& c = e.layers.sum;
    const auto term = [&out](const char* name, const Color& value) {
        say(out, "  %-13s %s\n", name, vec(value).c_str());
    };
    term("ambient", c.ambient);
    term("diffuse", c.diffuse);
    term("specular", c.specular);
    term("mirror", c.mirror);
    term("transmission", c.transmission);
    term("background", c.background);
    for (size_t k = 0; k < c.lights.size(); ++k)
        say(out, "  %-13s %s  (diffuse + specular of %s at the first hit)\n", fmt::format("light{}", k + 1).c_str(),
            vec(c.lights[k]).c_str(), light_label(scene, k).c_str());
    say(out, "  pixel         %s  (the EXR's R, G, B: %s)\n", vec(e.pixel).c_str(),
        fmt::format("({}, {}, {})", e.rgb[0], e.rgb[1], e.rgb[2]).c_str());
    say(out, "(whitted explain without --summary: every sample, segment and light with its numbers)\n");
}

nlohmann::json to_json(const Scene& scene, const std::string& path, const PixelExplanation& e) {
    using nlohmann::json;
    json samples = json::array();
    for (const ExplainedSample& sample : e.samples) {
        json segments = json::array();
        for (const ExplainedSegment& s : sample.segments) {
            json j = {{"level", s.level}, {"ray", jray(s.ray)}, {"weight", jvec(s.weight)}, {"hit", s.hit}};
            if (!s.hit) {
                j["background"] = jvec(scene.background);
                j["seen"] = jvec(s.seen);
                segments.push_back(j);
                continue;
            }
            const Material& m = scene.materials[s.surface.material];
            const Vec3 v = -s.ray.direction;
            j["object"] = jobject(scene, s.surface.object);
            j["material"] = {{"id", s.surface.material + 1},
                             {"name", scene.material_names[s.surface.material]},
                             {"ka", jvec(m.ka)},
                             {"kd", jvec(m.kd)},
                             {"ks", jvec(m.ks)},
                             {"p", m.p},
                             {"km", jvec(m.km)},
                             {"highlight", m.highlight == Highlight::blinn ? "blinn" : "phong"}};
            j["t"] = s.surface.t;
            j["point"] = jvec(s.surface.point);
            j["normal"] = jvec(s.normal);
            j["geometric_normal"] = jvec(s.surface.geometric_normal);
            j["to_eye"] = jvec(v);
            j["ambient_light"] = jvec(scene.ambient);
            j["ambient"] = jvec(s.ambient);
            json lights = json::array();
            for (const ExplainedLight& l : s.lights) {
                const LightTerms& t = l.terms;
                const Light& light = scene.lights[l.light];
                json jl = {{"light", l.light + 1},
                           {"type", light.type == LightType::point ? "point" : "directional"},
                           {"intensity", jvec(light.intensity)},
                           {"l", jvec(t.to_light)},
                           {"n_dot_l", t.n_dot_l},
                           {"facing", t.facing},
                           {"shadow_ray", t.facing ? jray(t.shadow_ray) : json(nullptr)},
                           {"shadow_tested", t.shadow_tested},
                           {"blocked", t.blocked},
                           {"blocker", nullptr},
                           {"diffuse", jvec(t.diffuse)},
                           {"specular", jvec(t.specular)}};
                if (light.type == LightType::point) jl["position"] = jvec(light.position);
                if (t.facing) {
                    const Lobe lobe = lobe_of(m, s.normal, v, t.to_light);
                    jl[m.highlight == Highlight::blinn ? "h" : "r_v"] = jvec(lobe.vector);
                    jl[m.highlight == Highlight::blinn ? "n_dot_h" : "r_v_dot_l"] = lobe.cosine;
                    jl["lobe"] = lobe.value;
                }
                if (l.blocker) jl["blocker"] = {{"object", jobject(scene, l.blocker->object)}, {"t", l.blocker->t}};
                lights.push_back(jl);
            }
            j["lights"] = lights;
            j["local"] = jvec(s.local);
            j["added"] = jvec(s.added);
            j["mirror"] = s.mirrored
                              ? json{{"km", jvec(m.km)}, {"ray", jray(s.mirror_ray)}, {"weight", jvec(s.mirror_weight)}}
                              : json(nullptr);
            j["refracted"] = s.transmitted ? json{{"kt", jvec(m.kt)},
                                                  {"ior", m.ior},
                                                  {"ray", jray(s.refracted_ray)},
                                                  {"weight", jvec(s.refracted_weight)}}
                                           : json(nullptr);
            segments.push_back(j);
        }
        samples.push_back({{"sample", sample.sample}, {"segments", segments}, {"radiance", jvec(sample.radiance)}});
    }
    const PathLayers& c = e.layers.sum;
    json lights = json::array();
    for (const Color& light : c.lights) lights.push_back(jvec(light));
    return {{"scene", std::filesystem::path(path).filename().string()},
            {"x", e.x},
            {"y", e.y},
            {"width", scene.width},
            {"height", scene.height},
            {"samples_per_side", scene.samples},
            {"max_depth", scene.max_depth},
            {"background", jvec(scene.background)},
            {"samples", samples},
            {"sum", jvec(e.sum)},
            {"pixel", jvec(e.pixel)},
            {"rgb", {double(e.rgb[0]), double(e.rgb[1]), double(e.rgb[2])}},
            {"layers",
             {{"ambient", jvec(c.ambient)},
              {"diffuse", jvec(c.diffuse)},
              {"specular", jvec(c.specular)},
              {"mirror", jvec(c.mirror)},
              {"transmission", jvec(c.transmission)},
              {"background", jvec(c.background)},
              {"lights", lights},
              {"beauty", {double(e.layer_beauty[0]), double(e.layer_beauty[1]), double(e.layer_beauty[2])}}}}};
}

/// JSON has no number for infinity or NaN (nlohmann writes them as null, which the schema
/// refuses): a legal scene can still produce them (a colour of 1e300 overflows the float pixel),
/// so each is written as the string "inf", "-inf" or "nan", as docs/explain.schema.json allows.
void name_non_finite_numbers(nlohmann::json& j) {
    if (j.is_number_float()) {
        const double d = j.get<double>();
        if (std::isnan(d))
            j = "nan";
        else if (std::isinf(d))
            j = d > 0 ? "inf" : "-inf";
    } else if (j.is_structured()) {
        for (nlohmann::json& child : j) name_non_finite_numbers(child);
    }
}

/// The explanation as JSON text. Names may be Latin-1 (MTL files): bytes that are not UTF-8 are
/// written as U+FFFD, so that the output is JSON whatever the scene holds.
std::string json_text(const Scene& scene, const std::string& path, const PixelExplanation& explanation) {
    nlohmann::json document = to_json(scene, path, explanation);
    name_non_finite_numbers(document);
    return document.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

namespace api {

Expected<std::string> explain(const Scene& scene, int x, int y, const ExplainOptions& options) {
    const whitted::Scene& traced = impl_of(scene).scene;
    if (x < 0 || y < 0 || x >= traced.width || y >= traced.height)
        return Error{fmt::format("pixel {},{} is outside the {}x{} image (X 0..{}, Y 0..{})", x, y, traced.width,
                                 traced.height, traced.width - 1, traced.height - 1),
                     scene.path()};
    try {
        const PixelExplanation explanation = explain_pixel(traced, impl_of(scene).accelerator(options.threads), x, y);
        std::string out;
        switch (options.format) {
            case ExplainFormat::text:
                write_text(out, traced, scene.path(), explanation);
                break;
            case ExplainFormat::summary:
                write_summary(out, traced, scene.path(), explanation);
                break;
            case ExplainFormat::json:
                out = json_text(traced, scene.path(), explanation) + "\n";
                break;
        }
        return out;
    } catch (...) {  // e.g. an InputError: a shape beyond the range the accelerator takes
        return current_error({"explaining a pixel of " + scene.path(), scene.path()});
    }
}

}  // namespace api

}  // namespace whitted
