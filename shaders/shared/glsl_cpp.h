// Lets one header be included by both GLSL and C++ (STYLE.md habit 1): in C++ the GLSL
// vector and scalar type names map to glm and <cstdint> types, so a struct written once has
// the same std430 layout on both sides. Only use vec4/uvec4/ivec4 and scalars in shared
// structs: vec3 has implicit padding in std430 and is banned there.
#ifndef SDFSTREAM_GLSL_CPP_H
#define SDFSTREAM_GLSL_CPP_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>
namespace sdfstream::gpu_shared {
using uint = std::uint32_t;
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using ivec3 = glm::ivec3;
using ivec4 = glm::ivec4;
using uvec2 = glm::uvec2;
using uvec3 = glm::uvec3;
using uvec4 = glm::uvec4;
}  // namespace sdfstream::gpu_shared
#define SDF_CONST static constexpr
#define SDF_BEGIN_NAMESPACE namespace sdfstream::gpu_shared {
#define SDF_END_NAMESPACE }
#else
#define SDF_CONST const
#define SDF_BEGIN_NAMESPACE
#define SDF_END_NAMESPACE
#endif

#endif
