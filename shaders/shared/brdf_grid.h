// Input/output records of shaders/test/brdf_grid.comp, shared by GLSL and C++ (GLM). Only vec4 members,
// so the std430 layout is the C++ layout: a 16-byte stride per vec4, no padding (static_asserts below).
#ifndef RTR_SHADERS_SHARED_BRDF_GRID_H
#define RTR_SHADERS_SHARED_BRDF_GRID_H

#ifdef __cplusplus
#include <glm/vec4.hpp>
namespace rtr::shader {
using glm::vec4;
#endif

#define BRDF_GRID_LOCAL_SIZE 64
#define BRDF_GRID_BINDING_IN 0   // set 0: readonly std430 buffer of BrdfGridInput[]
#define BRDF_GRID_BINDING_OUT 1  // set 0: std430 buffer of BrdfGridOutput[], same length

struct BrdfGridInput {
  vec4 n;           // xyz: normal (any length, may be zero)
  vec4 v;           // xyz: unit direction towards the viewer
  vec4 l;           // xyz: unit direction towards the light
  vec4 baseColor;   // rgb
  vec4 params;      // x: roughness, y: metalness, z: BRDF_BECKMANN or BRDF_GGX
  vec4 lightColor;  // rgb
  vec4 ambient;     // rgb
  vec4 emissive;    // rgb
};

struct BrdfGridOutput {
  vec4 DG;        // x: D, y: G
  vec4 F;         // rgb
  vec4 diffuse;   // rgb
  vec4 specular;  // rgb
  vec4 radiance;  // rgb: shadePbr
};

#ifdef __cplusplus
static_assert(sizeof(BrdfGridInput) == 8 * 16 && alignof(BrdfGridInput) <= 16);
static_assert(sizeof(BrdfGridOutput) == 5 * 16 && alignof(BrdfGridOutput) <= 16);
}  // namespace rtr::shader
#endif

#endif
