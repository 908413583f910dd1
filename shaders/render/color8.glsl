// 8-bit colour helpers shared by the mip and post shaders: the exact sRGB encode and a
// rounding that makes the stored byte independent of the hardware's float -> UNORM rounding.
#ifndef RTR_RENDER_COLOR8_GLSL
#define RTR_RENDER_COLOR8_GLSL

float linearToSrgb(float c) {
  return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

// Round to the nearest of the 256 levels here (ties up, like rtr::encodeTexel), then store q + 1/4:
// both round-to-nearest and truncating float -> UNORM conversions turn that into q.
vec4 quantize8(vec4 v) {
  return (floor(clamp(v, 0.0, 1.0) * 255.0 + 0.5) + 0.25) / 255.0;
}

// Linear value -> what to store through a UNORM view (R, G, B sRGB-encoded when srgb; alpha linear).
vec4 encode8(vec4 linear, bool srgb) {
  vec4 c = clamp(linear, 0.0, 1.0);
  if (srgb) c = vec4(linearToSrgb(c.r), linearToSrgb(c.g), linearToSrgb(c.b), c.a);
  return quantize8(c);
}

#endif
