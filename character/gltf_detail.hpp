#pragma once
// Inside character/: reading validated accessor data out of a tinygltf model.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "character/tinygltf_config.hpp"

namespace marionette::character::detail {

// Each throws ImportError(file, 0, "<what>: ...") naming the accessor (by its
// index and role, e.g. "accessor 3 (POSITION)") and what is wrong: index out of
// range, sparse, wrong type or component type, a view or buffer too short,
// non-finite numbers.
std::vector<std::array<float, 3>> read_vec3(const tinygltf::Model& m, int accessor, const std::string& what,
                                            const std::string& file);
// Joint indices (VEC4 of unsigned byte or short).
std::vector<std::array<std::uint16_t, 4>> read_joints(const tinygltf::Model& m, int accessor, const std::string& what,
                                                      const std::string& file);
// Weights (VEC4 of float, or normalised unsigned byte/short), each finite and ≥ 0.
std::vector<std::array<float, 4>> read_weights(const tinygltf::Model& m, int accessor, const std::string& what,
                                               const std::string& file);
// Triangle indices (SCALAR of unsigned byte, short or int).
std::vector<std::uint32_t> read_indices(const tinygltf::Model& m, int accessor, const std::string& what,
                                        const std::string& file);
// Column-major 4×4 matrices (MAT4 of float).
std::vector<std::array<float, 16>> read_mat4(const tinygltf::Model& m, int accessor, const std::string& what,
                                             const std::string& file);

}  // namespace marionette::character::detail
