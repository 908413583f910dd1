#version 460
// Inline ray tracing: an acceleration structure read by a compute shader.
#extension GL_EXT_ray_query : require
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(set = 0, binding = 1, r32f) uniform writeonly image2D shadow;
void main() {
  rayQueryEXT q;
  rayQueryInitializeEXT(q, scene, gl_RayFlagsTerminateOnFirstHitEXT, 0xff, vec3(gl_GlobalInvocationID), 0.0, vec3(0, 1, 0), 100.0);
  while (rayQueryProceedEXT(q)) {}
  float lit = rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionNoneEXT ? 1.0 : 0.0;
  imageStore(shadow, ivec2(gl_GlobalInvocationID.xy), vec4(lit));
}
