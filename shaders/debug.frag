#version 460
#extension GL_GOOGLE_include_directive : require
// Debug views (modes 2-15), in their own pipelines so the shaded path stays free of them. Values are
// written so that the displayed 8-bit sRGB value is the quantity itself (the post pass encodes sRGB),
// except the radiances (albedo, the environment's terms), written linear like the shaded view.
#include "material.glsl"
#include "brdf.h"
#include "env_light.glsl"

layout(location = 0) out vec4 outColor;

vec3 displayed(vec3 x) {  // inverse of the sRGB encode of the post pass
  x = clamp(x, 0.0, 1.0);
  return mix(x / 12.92, pow((x + 0.055) / 1.055, vec3(2.4)), greaterThan(x, vec3(0.04045)));
}

// Colour code of a mip level (legend in docs/viewer.md): 0 blue, 1 cyan, 2 green, 3 yellow, 4 orange,
// 5 red, 6 magenta, 7+ white; fractional levels blend the two neighbours.
vec3 mipColor(float level) {
  const vec3 k[8] = vec3[8](vec3(0, 0, 1), vec3(0, 1, 1), vec3(0, 1, 0), vec3(1, 1, 0), vec3(1, 0.5, 0),
                            vec3(1, 0, 0), vec3(1, 0, 1), vec3(1, 1, 1));
  float l = clamp(level, 0.0, 7.0);
  int i = int(floor(l));
  return mix(k[i], k[min(i + 1, 7)], l - float(i));
}

void main() {
  Surface s = fetchSurface();
  if (ALPHA_MASK) {  // a branch on the constant alone, which specialization folds
    if (cutOut(s)) discard;
  }
  int mode = int(frame.params.x);
  vec3 n = brdfSafeNormal(shadingNormal(s));
  vec3 v = normalize(frame.cameraPos.xyz - inWorldPos);
  // The first light (a scene without lights: the view direction, as a headlight).
  vec3 l = frame.lightCount.x == 0u              ? v
           : frame.lights[0].color.w > 3.5 ? -frame.lights[0].direction.xyz  // LIGHT_DIRECTIONAL
                                           : normalize(frame.lights[0].position.xyz - inWorldPos);
  float viewDepth = -(frame.view * vec4(inWorldPos, 1.0)).z;  // distance along the view axis
  float far = frame.params.w;
  vec3 c = vec3(0.0);
  if (mode == VIEW_MIP_LEVEL) {
    uint t = materials[draw.material].textures.x;
    if (!HAS_TEXCOORDS) {
      c = vec3(0.5);  // no texture coordinates: no mip level
    } else if (t == NO_TEXTURE) {
      c = vec3(0.5);
    } else {
      vec2 q = textureQueryLod(textures[t], inTexcoord);
      float level = q.x + frame.params.y;
      // Nearest mip: the level the biased LOD rounds to (Vulkan: ceil(lod + 0.5) - 1), as the lookup takes.
      if (frame.lightCount.y != 0u)
        level = ceil(clamp(q.y + frame.params.y, 0.0, float(textureQueryLevels(textures[t]) - 1)) + 0.5) - 1.0;
      c = mipColor(level);
    }
  } else if (mode == VIEW_LINEAR_DEPTH) {
    c = vec3(viewDepth / far);
  } else if (mode == VIEW_DEPTH_DERIVATIVES) {
    // Screen-space slope of linear depth, relative to the depth itself (scale-free), amplified.
    c = vec3(abs(dFdx(viewDepth)), abs(dFdy(viewDepth)), 0.0) * (50.0 / max(viewDepth, 1e-6));
  } else if (mode == VIEW_NORMAL) {
    c = abs(n);
  } else if (mode == VIEW_VIEW_DIR) {
    c = v * 0.5 + 0.5;
  } else if (mode == VIEW_LIGHT_DIR) {
    c = l * 0.5 + 0.5;
  } else if (mode == VIEW_ALBEDO) {
    outColor = vec4(s.baseColor, 1.0);  // linear, like the shaded output
    return;
  } else if (mode == VIEW_ENV_DIFFUSE || mode == VIEW_ENV_SPECULAR) {
    // The two terms the shaded view adds for the environment, so that they sum to its share (0 without one).
    vec3 diffuse = vec3(0.0), specular = vec3(0.0);
    if (HAS_ENV) envLightTerms(brdfOf(), n, v, s.baseColor, s.roughness, s.metalness, s.occlusion, diffuse, specular);
    outColor = vec4(min(mode == VIEW_ENV_DIFFUSE ? diffuse : specular, vec3(60000.0)), 1.0);
    return;
  } else {
    BrdfTerms t = brdfTerms(brdfOf(), n, v, l, s.baseColor, s.roughness, s.metalness);
    if (mode == VIEW_BRDF_D) c = vec3(t.D / (1.0 + t.D));  // tone-mapped: D is unbounded
    else if (mode == VIEW_BRDF_F) c = t.F;
    else if (mode == VIEW_BRDF_G) c = vec3(t.G);
    else if (mode == VIEW_DIFFUSE) c = t.diffuse * BRDF_PI;
    else if (mode == VIEW_SPECULAR) c = t.specular / (1.0 + t.specular);
  }
  outColor = vec4(displayed(c), 1.0);
}
