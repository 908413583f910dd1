#version 460
// Visibility path, shading in compute (ShadingPath::Visibility, mode 1): one thread per pixel reads the
// visible triangle's ids, rebuilds the triangle from the index and vertex buffers, intersects the pixel's
// ray with it for perspective-correct barycentrics, and shades with the same brdf.h as pbr.frag.
// Texture LOD: the texcoord differences to the quad neighbour, like the rasteriser's fine derivatives
// (docs/shading.md, "Visibility path").
// MATERIAL_EXTRAS (variants.h): only a scene with glTF's material extras gets the code for them; the
// others (OBJ, the course's format) sample set 0's texcoords untransformed, as the identity would.
// DISPLAY (variants.h): where nothing else reads the linear image (mosaic off, no transparent pass), the
// pass writes the target's bytes itself, as the post pass's copy would (Renderer::frame).
// IDENTITY (variants.h): every instance is the identity (a scene without instances): of the instance record
// only its info is read, and no transform is applied; the product with an exact identity gives the same
// values except a -0 coordinate turned +0, which no result here depends on (tested byte for byte).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_nonuniform_qualifier : require
#extension GL_EXT_samplerless_texture_functions : require
#include "frame.h"
#include "brdf.h"
#include "variants.h"
#include "render/color8.glsl"

layout(local_size_x = VIS_GROUP_X, local_size_y = VIS_GROUP_Y) in;

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 1, std430) readonly buffer Materials { GpuMaterial materials[]; };
layout(set = 0, binding = 2, std430) readonly buffer Draws { GpuDraw draws[]; };
layout(set = 0, binding = 3, std430) readonly buffer Positions { float positions[]; };
layout(set = 0, binding = 4, std430) readonly buffer Normals { float normals[]; };
layout(set = 0, binding = 5, std430) readonly buffer Indices32 { uint indices32[]; };
layout(set = 0, binding = 6, std430) readonly buffer Indices16 { uint indices16[]; };  // two per word
// The ids, by VIS_BUFFER: the hardware rasteriser's image, or the compute rasteriser's (depth << 32 | id)
// per pixel, row by row (raster.h).
layout(set = 0, binding = 7) uniform utexture2D visibilityImage;
// pc.clearIds: each word read is written back clear (RASTER_CLEAR), so that the next frame's compute
// rasteriser need not clear the buffer (ComputeRaster::foldClear): set where nothing reads the ids after this
// pass. A store to the 8 bytes just read (an empty pixel's are clear already), waited for by nothing here.
layout(set = 0, binding = 14, std430) buffer Visibility { uvec2 visibilityBuffer[]; };  // x: the low half
layout(set = 0, binding = 8, rgba16f) writeonly uniform image2D sceneColor;
layout(set = 0, binding = 16) writeonly uniform image2D displayImage;  // DISPLAY: the target (UNORM; BGRA too)
// HAS_TEXCOORDS only:
layout(set = 0, binding = 9, std430) readonly buffer Texcoords { vec2 texcoords[]; };
layout(set = 1, binding = 0) uniform sampler2D textures[];
layout(set = 0, binding = 10, std430) readonly buffer Instances { GpuInstance instances[]; };
// glTF's streams where the draw has them (GpuDraw flags); scenes without bind any buffer.
layout(set = 0, binding = 11, std430) readonly buffer Texcoords1 { vec2 texcoords1[]; };
layout(set = 0, binding = 12, std430) readonly buffer Tangents { vec4 tangents[]; };
layout(set = 0, binding = 13, std430) readonly buffer Colors { vec4 colors[]; };
layout(set = 0, binding = 15, std430) readonly buffer IdPages { uint idPages[]; };  // GpuScene::visIdPages
layout(push_constant) uniform Push { VisShadePush pc; };
#include "env_light.glsl"

const float kMaxRadiance = 60000.0;  // as pbr.frag: stay below the half-float maximum

ivec2 outputSize() { return DISPLAY ? imageSize(displayImage) : imageSize(sceneColor); }

// x rounded to the nearest half float (ties to even), as a float. In integers: a compiler may fold
// packHalf2x16 into the image store's conversion, whose rounding the device picks (lavapipe truncates).
float toHalf(float x) {
  if (abs(x) < 6.103515625e-05) return roundEven(x * 16777216.0) / 16777216.0;  // half subnormals: steps of 2^-24
  const uint b = floatBitsToUint(x);
  return uintBitsToFloat((b + 0xFFFu + ((b >> 13) & 1u)) & ~0x1FFFu);  // 10 of the 23 mantissa bits kept
}

// The pixel's radiance as the half floats the linear image holds, rounded here, so the store converts
// exactly; DISPLAY: those values sRGB-encoded to 8 bits as the post pass's copy (mosaic.comp, block 1x1)
// encodes them, so the bytes are the same.
void store(ivec2 p, vec3 c) {
  c = min(c, vec3(kMaxRadiance));
  const vec3 h = vec3(toHalf(c.r), toHalf(c.g), toHalf(c.b));
  if (DISPLAY) imageStore(displayImage, p, encode8(vec4(h, 1.0), true));
  else imageStore(sceneColor, p, vec4(h, 1.0));
}

vec3 position(uint i) { return vec3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); }
vec3 normal(uint i) { return vec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]); }

uint vertexIndex(GpuDraw d, uint i) {
  if ((d.flags & DRAW_INDEX16) == 0u) return indices32[d.firstIndex + i];
  uint k = d.firstIndex + i;
  return (indices16[k >> 1] >> ((k & 1u) * 16u)) & 0xFFFFu;  // little-endian halves
}

// Barycentrics (of vertices 0, 1, 2) where the ray o + t dir meets the triangle's plane. With
// s = o - p0: u = dir.(e2 x s) / det, v = dir.(s x e1) / det, det = -dir.(e1 x e2); any scale of dir
// gives the same result. The guard keeps a ray parallel to the plane finite.
vec3 barycentrics(vec3 dir, vec3 a, vec3 b, vec3 n) {
  float det = -dot(dir, n);
  float inv = 1.0 / (abs(det) > 1e-30 ? det : 1e-30);
  vec2 uv = clamp(vec2(dot(dir, a), dot(dir, b)) * inv, -1e4, 1e4);
  return vec3(1.0 - uv.x - uv.y, uv);
}

// Texcoords of both sets and their differences to the quad neighbours (x, y): uv[0..2] set 0, uv[3..5] set 1.
vec4 sampleOr(uint material, uint index, uint slot, vec2 uv[6], vec4 fallback) {
  if (index == NO_TEXTURE) return fallback;
  if (!MATERIAL_EXTRAS) return textureGrad(textures[nonuniformEXT(index)], uv[0], uv[1], uv[2]);  // set 0, identity
  const vec4 r0 = materials[material].uvTransform[2 * slot], r1 = materials[material].uvTransform[2 * slot + 1];
  const int k = r0.w > 0.5 ? 3 : 0;
  const mat2 a = mat2(r0.x, r1.x, r0.y, r1.y);  // the transform's linear part (columns)
  return textureGrad(textures[nonuniformEXT(index)], a * uv[k] + vec2(r0.z, r1.z), a * uv[k + 1], a * uv[k + 2]);
}

// The instance whose id range holds `id` (frame.h): between its page's entry and the next page's.
uint instanceOf(uint id) {
  const uint page = id >> pc.idPageShift;
  uint lo = idPages[page], hi = idPages[page + 1u];
  while (lo < hi) {
    const uint mid = (lo + hi + 1u) >> 1u;
    if (instances[mid].info.z <= id) lo = mid;
    else hi = mid - 1u;
  }
  return lo;
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, outputSize()))) return;
  uint packed;
  if (VIS_BUFFER) {
    const uint i = p.y * outputSize().x + p.x;
    const uvec2 word = visibilityBuffer[i];
    packed = word.x;
    if (pc.clearIds != 0u && word != uvec2(~0u)) visibilityBuffer[i] = uvec2(~0u);
  } else {
    packed = texelFetch(visibilityImage, p, 0).x;
  }
  const vec3 dir = frame.rayDir.xyz + (vec2(p) + 0.5).x * frame.rayDx.xyz + (vec2(p) + 0.5).y * frame.rayDy.xyz;
  if (packed == VIS_EMPTY) {  // the backdrop: the forward pass's clear colour, or the environment
    store(p, HAS_ENV ? envBackdrop(dir) : frame.background.rgb);
    return;
  }
  const uint ii = instanceOf(packed);
  const uvec4 info = instances[ii].info;
  const GpuDraw d = draws[info.x];
  const uint first = 3u * (packed - info.z);
  const uvec3 tri = uvec3(vertexIndex(d, first), vertexIndex(d, first + 1u), vertexIndex(d, first + 2u)) + d.vertexOffset;
  // Scene space, computed as the vertex stages do.
  const mat4 transform = IDENTITY ? mat4(1.0) : instances[ii].transform;
  vec3 p0 = position(tri.x), p1 = position(tri.y), p2 = position(tri.z);
  if (!IDENTITY) p0 = (transform * vec4(p0, 1.0)).xyz, p1 = (transform * vec4(p1, 1.0)).xyz, p2 = (transform * vec4(p2, 1.0)).xyz;
  const vec3 e1 = p1 - p0, e2 = p2 - p0, s = frame.cameraPos.xyz - p0;
  const vec3 n = cross(e1, e2), a = cross(e2, s), b = cross(s, e1);

  const vec3 w = clamp(barycentrics(dir, a, b, n), 0.0, 1.0);  // the rasteriser covered this pixel centre
  const vec3 worldPos = p0 * w.x + p1 * w.y + p2 * w.z;
  // Two-sided materials light their back faces with the flipped normal (front: counter-clockwise seen
  // from the camera, as the forward pipelines' VK_FRONT_FACE_COUNTER_CLOCKWISE; clockwise for a mirrored
  // instance, whose draws set VK_FRONT_FACE_CLOCKWISE).
  vec3 nrm = normal(tri.x) * w.x + normal(tri.y) * w.y + normal(tri.z) * w.z;
  if (!IDENTITY) nrm = mat3(instances[ii].normalX.xyz, instances[ii].normalY.xyz, instances[ii].normalZ.xyz) * nrm;
  const bool back = (dot(n, s) < 0.0) != ((info.y & INSTANCE_MIRRORED) != 0u);
  if (back) nrm = -nrm;

  // The record's members one by one, the texture transforms only where sampled (sampleOr): a copy of the
  // whole record loads its 304 bytes (the SPIR-V keeps the whole-struct load; dropping the unused parts is
  // left to the driver).
  const uint mi = d.material;
  GpuMaterial m;
  m.baseColor = materials[mi].baseColor;
  m.emissive = materials[mi].emissive;
  m.roughMetal = materials[mi].roughMetal;
  m.textures = materials[mi].textures;
  m.textures2 = materials[mi].textures2;
  vec3 baseColor = m.baseColor.rgb, emissive = m.emissive.rgb;
  float roughness = m.roughMetal.x, metalness = m.roughMetal.y, occlusion = 1.0;
  if (MATERIAL_EXTRAS && (d.flags & DRAW_COLORS) != 0u) baseColor *= (colors[tri.x] * w.x + colors[tri.y] * w.y + colors[tri.z] * w.z).rgb;
  if (HAS_TEXCOORDS && (d.flags & DRAW_TEXTURED) != 0u) {
    const vec2 t0 = texcoords[tri.x], t1 = texcoords[tri.y], t2 = texcoords[tri.z];
    const vec2 uv = t0 * w.x + t1 * w.y + t2 * w.z;
    // Differences to the other pixel of the 2x2 quad in x and in y (what fine dFdx/dFdy give), scaled
    // by 2^bias: textureGrad has no bias argument, and the LOD is log2 of the gradient's length.
    const vec2 side = vec2(1 - 2 * (p & 1));
    const vec3 wx = barycentrics(dir + side.x * frame.rayDx.xyz, a, b, n);
    const vec3 wy = barycentrics(dir + side.y * frame.rayDy.xyz, a, b, n);
    const float scale = exp2(frame.params.y);
    const vec2 gx = (t0 * wx.x + t1 * wx.y + t2 * wx.z - uv) * (side.x * scale);
    const vec2 gy = (t0 * wy.x + t1 * wy.y + t2 * wy.z - uv) * (side.y * scale);
    vec2 uvs[6] = vec2[6](uv, gx, gy, uv, gx, gy);
    if (MATERIAL_EXTRAS && (d.flags & DRAW_UV1) != 0u) {
      const vec2 s0 = texcoords1[tri.x], s1 = texcoords1[tri.y], s2 = texcoords1[tri.z];
      uvs[3] = s0 * w.x + s1 * w.y + s2 * w.z;
      uvs[4] = (s0 * wx.x + s1 * wx.y + s2 * wx.z - uvs[3]) * (side.x * scale);
      uvs[5] = (s0 * wy.x + s1 * wy.y + s2 * wy.z - uvs[3]) * (side.y * scale);
    }
    baseColor *= sampleOr(mi, m.textures.x, SLOT_BASE, uvs, vec4(1.0)).rgb;
    roughness *= sampleOr(mi, m.textures.y, SLOT_ROUGHNESS, uvs, vec4(1.0)).r;
    metalness *= sampleOr(mi, m.textures.z, SLOT_METALNESS, uvs, vec4(1.0)).r;
    emissive *= sampleOr(mi, m.textures2.x, SLOT_EMISSIVE, uvs, vec4(1.0)).rgb;
    if (MATERIAL_EXTRAS && m.textures2.y != NO_TEXTURE) occlusion = 1.0 + m.roughMetal.w * (sampleOr(mi, m.textures2.y, SLOT_OCCLUSION, uvs, vec4(1.0)).r - 1.0);
    if (MATERIAL_EXTRAS && m.textures2.z != NO_TEXTURE && (d.flags & DRAW_TANGENTS) != 0u) {
      // As material.glsl: t, b = w (n x t), n; the map's xy scaled by normalScale.
      const vec4 tg = tangents[tri.x] * w.x + tangents[tri.y] * w.y + tangents[tri.z] * w.z;
      const vec3 tn = (sampleOr(mi, m.textures2.z, SLOT_NORMAL, uvs, vec4(0.5, 0.5, 1.0, 1.0)).xyz * 2.0 - 1.0) *
                      vec3(m.emissive.w, m.emissive.w, 1.0);
      const vec3 nn = normalize(back ? -nrm : nrm), t3 = mat3(transform) * tg.xyz;
      const vec3 t = normalize(t3 - nn * dot(nn, t3));
      const float sgn = (info.y & INSTANCE_MIRRORED) != 0u ? -tg.w : tg.w;
      nrm = t * tn.x + cross(nn, t) * (sgn * tn.y) + nn * tn.z;
      if (back) nrm = -nrm;
    }
  }
  if (MATERIAL_EXTRAS && (m.textures2.w & MATERIAL_UNLIT) != 0u) {
    store(p, baseColor);
    return;
  }

  const vec3 v = normalize(frame.cameraPos.xyz - worldPos);
  const int brdf = frame.options.x != 0u                                         ? int(frame.options.x) - 1
                   : MATERIAL_EXTRAS && (m.textures2.w & MATERIAL_GGX) != 0u ? BRDF_GGX
                                                                              : BRDF_BECKMANN;
  vec3 c = frame.ambient.rgb * clamp(baseColor, vec3(0.0), vec3(1.0)) * occlusion + emissive;
  for (uint i = 0u; i < frame.lightCount.x; ++i) {
    const LightSample ls = lightSample(frame.lights[i], worldPos);  // point, spot or directional (lights.h)
    c += pbrDirect(brdf, nrm, v, ls.l, ls.radiance, baseColor, roughness, metalness);
  }
  if (HAS_ENV) c += envLight(brdf, nrm, v, baseColor, roughness, metalness, occlusion);
  store(p, c);
}
