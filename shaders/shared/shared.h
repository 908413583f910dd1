// Qualifiers for headers compiled both as GLSL and as C++ (GLM): RTR_FN for functions, RTR_CONST for
// constants. Include it before opening namespace rtr::shader.
#ifndef RTR_SHADERS_SHARED_SHARED_H
#define RTR_SHADERS_SHARED_SHARED_H
#ifdef __cplusplus
#include <glm/glm.hpp>
#define RTR_FN inline
#define RTR_CONST inline constexpr
#else
#define RTR_FN
#define RTR_CONST const
#endif
#endif
