// SPDX-License-Identifier: MIT
#include "scene/layer_names.h"

#include "scene/text_checks.h"

#include <stdexcept>

namespace whitted {

namespace {
const char* const names[layer_kinds] = {"ambient",    "diffuse", "specular", "mirror",     "transmission",
                                        "background", "lights",  "N",        "Ng",         "P",
                                        "Z",          "albedo",  "objectId", "materialId", "hits"};
}  // namespace

const char* layer_name(Layer layer) {
    return names[uint32_t(layer)];
}

std::optional<Layer> find_layer(const std::string& name) {
    for (int i = 0; i < layer_kinds; ++i)
        if (name == names[i]) return Layer(i);
    return std::nullopt;
}

std::string layer_choices() {
    std::string list = names[0];
    for (int i = 1; i < layer_kinds; ++i) list.append(", ").append(names[i]);
    return list;
}

LayerSet parse_layers(const std::vector<std::string>& entries) {
    LayerSet set;
    for (const std::string& entry : entries) {
        size_t start = 0;
        while (start <= entry.size()) {
            size_t end = entry.find(',', start);
            if (end == std::string::npos) end = entry.size();
            std::string name = entry.substr(start, end - start);
            while (!name.empty() && name.front() == ' ') name.erase(name.begin());
            while (!name.empty() && name.back() == ' ') name.pop_back();
            start = end + 1;
            if (name == "all") {
                set = LayerSet::all();
            } else if (name == "none") {
            } else if (const auto layer = find_layer(name)) {
                set.add(*layer);
            } else {
                std::vector<std::string> known = {"all", "none"};
                known.insert(known.end(), std::begin(names), std::end(names));
                throw std::invalid_argument("unknown render layer '" + printable(name) + "'" +
                                            did_you_mean(name, known) +
                                            "; use all, none, or some of: " + layer_choices());
            }
        }
    }
    return set;
}

}  // namespace whitted
