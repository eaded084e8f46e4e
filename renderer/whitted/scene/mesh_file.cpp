// SPDX-License-Identifier: MIT
#include "whitted/scene/mesh_file.h"

#include "whitted/scene/text_checks.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <unordered_map>

namespace whitted {

MeshData load_obj_mesh(const std::string& path, const SourceLocation& referenced_at) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (error || !std::filesystem::exists(status))
        throw InputError(referenced_at, "mesh file '" + path + "' not found");
    if (!std::filesystem::is_regular_file(status))
        throw InputError(referenced_at, "mesh file '" + path + "' is not a regular file");
    const auto size = std::filesystem::file_size(path, error);
    if (!error && static_cast<int64_t>(size) > limits::max_mesh_file_bytes)
        throw InputError(referenced_at, "mesh file '" + path + "' is " + std::to_string(size) +
                                            " bytes; the limit is " + std::to_string(limits::max_mesh_file_bytes));
    // Binary or non-UTF-8 garbage is refused before the OBJ reader guesses at it.
    check_text_is_readable(read_text_file(path, limits::max_mesh_file_bytes, "mesh file"), path);

    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    config.mtl_search_path = std::filesystem::path(path).parent_path().string();
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
        std::string message = reader.Error();
        while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
        throw InputError({path}, "cannot read the OBJ file: " + (message.empty() ? "unknown error" : message));
    }

    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    const size_t position_count = attrib.vertices.size() / 3;
    const size_t normal_count = attrib.normals.size() / 3;

    // tinyobjloader reads values beyond float range as inf; Embree's results are undefined for
    // non-finite vertices, and a NaN colour passes every range check.
    const auto require_finite = [&](const std::vector<tinyobj::real_t>& values, const char* what) {
        for (size_t i = 0; i < values.size(); ++i)
            if (!std::isfinite(values[i]))
                throw InputError({path}, std::string(what) + " " + std::to_string(i / 3 + 1) +
                                             " has a coordinate that is not a finite number (beyond float range?)");
    };
    require_finite(attrib.vertices, "vertex");
    require_finite(attrib.normals, "normal");

    MeshData mesh;
    for (const tinyobj::material_t& m : reader.GetMaterials()) {
        for (const tinyobj::real_t value : {m.ambient[0], m.ambient[1], m.ambient[2], m.diffuse[0], m.diffuse[1],
                                            m.diffuse[2], m.specular[0], m.specular[1], m.specular[2], m.shininess})
            if (!std::isfinite(value))
                throw InputError({path}, "material '" + m.name + "' has a value that is not a finite number");
        MaterialDescription material;
        material.name = m.name;
        material.where = {path};
        material.ka.value = {m.ambient[0], m.ambient[1], m.ambient[2]};
        material.kd.value = {m.diffuse[0], m.diffuse[1], m.diffuse[2]};
        material.ks.value = {m.specular[0], m.specular[1], m.specular[2]};
        // MTL allows Ns 0 (no highlight to speak of); the lecture's p must be > 0.
        material.p.value = m.shininess > 0 ? double(m.shininess) : 1.0;
        if (m.illum == 3) material.km.value = material.ks.value;
        mesh.materials.push_back(material);
    }

    bool all_have_normals = normal_count > 0;
    bool normals_follow_positions = true;
    size_t corner_count = 0;
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        size_t offset = 0;
        for (const unsigned char corners : shape.mesh.num_face_vertices) {
            if (corners != 3)
                throw InputError({path}, "face in '" + shape.name + "' has " + std::to_string(corners) +
                                             " vertices; faces need at least 3");
            for (size_t k = 0; k < 3; ++k) {
                const tinyobj::index_t& index = shape.mesh.indices[offset + k];
                if (index.vertex_index < 0 || static_cast<size_t>(index.vertex_index) >= position_count)
                    throw InputError({path}, "face refers to vertex " + std::to_string(index.vertex_index + 1) +
                                                 ", but the file has " + std::to_string(position_count) + " vertices");
                if (index.normal_index < 0) {
                    all_have_normals = false;
                } else if (static_cast<size_t>(index.normal_index) >= normal_count) {
                    throw InputError({path}, "face refers to normal " + std::to_string(index.normal_index + 1) +
                                                 ", but the file has " + std::to_string(normal_count) + " normals");
                } else if (index.normal_index != index.vertex_index) {
                    normals_follow_positions = false;
                }
            }
            offset += corners;
            corner_count += 3;
        }
    }
    if (corner_count == 0) throw InputError(referenced_at, "mesh file '" + path + "' has no faces");
    if (static_cast<int64_t>(corner_count / 3) > limits::max_triangles)
        throw InputError(referenced_at, "mesh file '" + path + "' has more than " +
                                            std::to_string(limits::max_triangles) + " triangles");

    const bool smooth = all_have_normals;
    const bool direct = !smooth || normals_follow_positions;
    if (direct) {
        mesh.positions.assign(attrib.vertices.begin(), attrib.vertices.end());
        if (smooth) {
            // A file may have fewer vn than v lines (vertices no face uses): copy what there is.
            const size_t copied = std::min(normal_count, position_count);
            mesh.normals.assign(attrib.normals.begin(), attrib.normals.begin() + 3 * copied);
            mesh.normals.resize(3 * position_count, 0.0f);
        }
    }
    // Otherwise: one vertex per distinct (position, normal) pair, so normals index like positions.
    std::unordered_map<uint64_t, uint32_t> pair_to_vertex;
    mesh.indices.reserve(corner_count);
    mesh.triangle_material.reserve(corner_count / 3);
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const auto& indices = shape.mesh.indices;
        for (size_t face = 0; face < shape.mesh.num_face_vertices.size(); ++face) {
            for (size_t k = 0; k < 3; ++k) {
                const tinyobj::index_t& index = indices[face * 3 + k];
                if (direct) {
                    mesh.indices.push_back(static_cast<uint32_t>(index.vertex_index));
                    continue;
                }
                const uint64_t key = (uint64_t(uint32_t(index.vertex_index)) << 32) | uint32_t(index.normal_index);
                auto [it, inserted] = pair_to_vertex.emplace(key, uint32_t(mesh.positions.size() / 3));
                if (inserted) {
                    for (int c = 0; c < 3; ++c) {
                        mesh.positions.push_back(attrib.vertices[3 * index.vertex_index + c]);
                        mesh.normals.push_back(attrib.normals[3 * index.normal_index + c]);
                    }
                }
                mesh.indices.push_back(it->second);
            }
            const int material = face < shape.mesh.material_ids.size() ? shape.mesh.material_ids[face] : -1;
            mesh.triangle_material.push_back(
                (material >= 0 && static_cast<size_t>(material) < mesh.materials.size()) ? material : -1);
        }
    }
    return mesh;
}

}  // namespace whitted
