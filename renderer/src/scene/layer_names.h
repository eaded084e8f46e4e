// SPDX-License-Identifier: MIT
#pragma once

// The names of the render layers (AOVs), as `render.layers` and `whitted render --layers` give
// them: part of what a scene may say, so the reader checks them here; what each layer holds and
// how it is recorded is render/layers.h (docs/layers.md).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace whitted {

/// The layers one can ask for, by their names in --layers and render.layers. `lights` stands for
/// one layer per light, light1, light2, ... (1-based, file order).
enum class Layer : uint32_t {
    ambient,       ///< ka·Ia at the first hit
    diffuse,       ///< Σ_i kd·I_i·max(0, n·l_i) at the first hit, over the unshadowed lights
    specular,      ///< Σ_i ks·I_i·max(0, n·h_i)^p at the first hit
    mirror,        ///< km·L(r): everything the first hit's mirror ray brings back, weighted
    transmission,  ///< kt·L(t): everything the first hit's refracted ray brings back, weighted
    background,    ///< the background colour where the camera ray misses
    lights,        ///< light<k>: light k's diffuse + specular at the first hit
    N,             ///< shading normal at the first hit, turned toward the camera ray
    Ng,            ///< geometric normal at the first hit, not turned
    P,             ///< world-space first hit point
    Z,             ///< camera ray distance t to the first hit; +inf on a miss
    albedo,        ///< kd of the first hit's material
    objectId,      ///< SceneObject number (1-based, file order) of the first hit; 0 on a miss
    materialId,    ///< Scene::materials index + 1 of the first hit's material; 0 on a miss
    hits,          ///< surface hits along the path (0 = the camera ray missed)
};
inline constexpr int layer_kinds = 15;

const char* layer_name(Layer layer);
std::optional<Layer> find_layer(const std::string& name);
/// "ambient, diffuse, ..." for messages and --help.
std::string layer_choices();

/// A set of layers.
struct LayerSet {
    uint32_t bits = 0;
    bool has(Layer layer) const { return bits & (1u << uint32_t(layer)); }
    void add(Layer layer) { bits |= 1u << uint32_t(layer); }
    bool empty() const { return bits == 0; }
    static LayerSet all() { return {(1u << layer_kinds) - 1}; }
};

/// "all", "none", or names separated by commas (and/or given as several list entries). Throws
/// std::invalid_argument naming a name that is none of the layers, with the closest name if one
/// is near, and listing them.
LayerSet parse_layers(const std::vector<std::string>& names);

}  // namespace whitted
