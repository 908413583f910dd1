// The project's two BRDFs, one material model (base colour, roughness, metalness; Schlick Fresnel):
//   * BRDF_BECKMANN, the brief's (part 2, §1.5): Lambertian diffuse + Cook-Torrance specular with the
//     Beckmann NDF and Cook-Torrance V-cavity masking. Course and OBJ scenes use it.
//   * BRDF_GGX, glTF 2.0's (spec Appendix B): Trowbridge-Reitz NDF with the height-correlated Smith
//     visibility, and the spec's metal-rough mix (diffuse weighted by the dielectric Fresnel). glTF
//     materials use it.
//
// This file is both GLSL 4.60 (#include "brdf.h" with GL_GOOGLE_include_directive) and C++20 with GLM
// (namespace rtr::shader), so the GPU renderer and the CPU reference ray tracer evaluate the same code.
// Keep it in the common subset: no in/out parameters, no swizzles, float literals with an f suffix,
// no GLSL keywords as names (sample, half, ...), struct members assigned one by one.
//
// Every result is finite and >= 0 for every input (see docs/shading.md for why each guard is needed):
//   * roughness 0 .. 1e-2: alpha = roughness^2 is clamped to BRDF_ALPHA_MIN;
//   * D uses tan^2(theta_h) (Beckmann) or sin^2(theta_h) (GGX) from the tangential part of the
//     unnormalised half vector (no 1 - cos^2 cancellation); Beckmann's is capped at BRDF_TAN2_MAX where D
//     underflows to 0 anyway;
//   * G / (4 n.v n.l) is cancelled algebraically (Beckmann) or has a floored denominator (GGX);
//   * |v + l|^2 is clamped to BRDF_HH_MIN inside the masking term only (v = -l, both grazing);
//   * light below the shading normal: f = 0; view below it: specular = 0, diffuse kept;
//   * n may be unnormalised or zero (zero n gives no direct light: ambient + emissive only).
#ifndef RTR_SHADERS_SHARED_BRDF_H
#define RTR_SHADERS_SHARED_BRDF_H

#include "shared.h"
#ifdef __cplusplus
namespace rtr::shader {
using namespace glm;
#endif

RTR_CONST float BRDF_PI = 3.14159265358979f;
// Smallest Beckmann alpha. Below it the lobe is narrower than a pixel at ordinary resolutions, and a
// point light would give D -> infinity at h = n (alpha = 0 is a delta: exactly zero almost everywhere).
// Clamping keeps a tiny finite highlight (peak D = 1/(pi alpha^2) ~ 3.2e5) instead of nothing.
RTR_CONST float BRDF_ALPHA_MIN = 1e-3f;
// Cap of tan^2(theta_h): exp(-1e4 / alpha^2) is 0 in float for alpha <= 1, so the cap never changes
// D; it only keeps (1 + tan^2)^2 finite when n.h -> 0.
RTR_CONST float BRDF_TAN2_MAX = 1e4f;
// Floor of |v + l|^2 in the masking term. |v + l| -> 0 only when v = -l; with both above the surface
// that forces n.v + n.l <= |v + l|, i.e. both within ~0.06 deg of the horizon, where the V-cavity model
// really diverges (forward grazing mirror). It bounds G / (4 n.v n.l) <= 4 / BRDF_HH_MIN.
RTR_CONST float BRDF_HH_MIN = 1e-6f;
// Floor of |n|^2 before normalising: a zero normal stays zero instead of becoming NaN.
RTR_CONST float BRDF_NN_MIN = 1e-30f;
// Floor of the height-correlated Smith denominator n.l Lambda_v + n.v Lambda_l >= alpha (n.v + n.l): it
// acts only with light and eye both within ~0.06 deg of the horizon, and bounds V_GGX <= 0.5 / 1e-6.
RTR_CONST float BRDF_GGX_VDEN_MIN = 1e-6f;

// Which BRDF (the first argument of brdfTerms, pbrDirect, shadePbr).
#define BRDF_BECKMANN 0
#define BRDF_GGX 1

struct BrdfTerms {
  float D;        // NDF at h (Beckmann or GGX)
  vec3 F;         // Schlick Fresnel
  float G;        // masking-shadowing, in [0, 1] (Cook-Torrance; GGX: height-correlated Smith, 4 n.v n.l V)
  vec3 diffuse;   // BRDF value f_diffuse (before the cosine)
  vec3 specular;  // BRDF value f_spec = D F G / (4 n.v n.l) (before the cosine)
};

// Alpha from the texture roughness (the brief and glTF: alpha = roughness^2), clamped to BRDF_ALPHA_MIN.
RTR_FN float brdfAlpha(float roughness) {
  float r = clamp(roughness, 0.0f, 1.0f);
  return max(r * r, BRDF_ALPHA_MIN);
}

// Unit normal, or zero for a zero-length one.
RTR_FN vec3 brdfSafeNormal(vec3 n) { return n * inversesqrt(max(dot(n, n), BRDF_NN_MIN)); }

// Beckmann D from the unnormalised half vector H = v + l and unit n:
// D = exp(-tan^2/alpha^2) / (pi alpha^2 cos^4) with 1/cos^4 = (1 + tan^2)^2. tan^2 = |H_t|^2 / (n.H)^2,
// H_t = H - (n.H) n, which keeps full precision near h = n (where tiny alphas need it).
RTR_FN float brdfBeckmannD(vec3 n, vec3 H, float alpha) {
  float nH = dot(n, H);
  vec3 Ht = H - nH * n;
  float ht2 = dot(Ht, Ht);
  float nH2 = nH * nH;
  // Division-free guard: if n.H = 0 the comparison fails and the cap is used.
  float t2 = (ht2 < BRDF_TAN2_MAX * nH2) ? ht2 / nH2 : BRDF_TAN2_MAX;
  float a2 = alpha * alpha;
  float d = exp(-t2 / a2) * (1.0f + t2) * (1.0f + t2) / (BRDF_PI * a2);
  return nH > 0.0f ? d : 0.0f;
}

// Cook-Torrance masking G = min(1, 2 (n.h)(n.v)/(v.h), 2 (n.h)(n.l)/(v.h)). With h = H/|H| and
// v.h = |H|/2 for unit v, l: (n.h)/(v.h) = 2 (n.H)/|H|^2, so G = min(1, 4 (n.H) min(nv, nl) / |H|^2).
RTR_FN float brdfMaskingG(float nv, float nl, float nH, float hh) {
  if (nv <= 0.0f || nl <= 0.0f) return 0.0f;
  float hhc = max(hh, BRDF_HH_MIN);
  return min(1.0f, 4.0f * max(nH, 0.0f) * min(nv, nl) / hhc);
}

// V = G / (4 n.v n.l), cancelled: with m = min(nv, nl), M = max(nv, nl), n.H = m + M,
//   G = 1 branch (|H|^2 <= 4 n.H m): V = 1 / (4 m M), and there m >= |H|/4 so 4 m M >= |H|^2/4;
//   G < 1 branch:                     V = n.H / (M |H|^2) = (1 + m/M) / |H|^2.
// Neither divides by a cosine that can be ~0, so V <= 4 / BRDF_HH_MIN.
RTR_FN float brdfVisibility(float nv, float nl, float nH, float hh) {
  if (nv <= 0.0f || nl <= 0.0f) return 0.0f;
  float hhc = max(hh, BRDF_HH_MIN);
  float m = min(nv, nl);
  float M = max(nv, nl);
  if (hhc <= 4.0f * nH * m) return 1.0f / (4.0f * m * M);
  // max(M, 1e-30): only a guard for denormal cosines on hardware that flushes them; m/M stays in [0, 1].
  return (1.0f + m / max(M, 1e-30f)) / hhc;
}

// Schlick: F = F0 + (1 - F0)(1 - v.h)^5, F0 = (1 - M) 0.04 + M c_mat.
RTR_FN vec3 brdfFresnel(float vh, vec3 baseColor, float metalness) {
  vec3 F0 = mix(vec3(0.04f), baseColor, metalness);
  float x = 1.0f - clamp(vh, 0.0f, 1.0f);
  float x2 = x * x;
  return F0 + (vec3(1.0f) - F0) * (x2 * x2 * x);
}

// GGX (Trowbridge-Reitz) D = alpha^2 / (pi (cos^2 (alpha^2 - 1) + 1)^2) from the unnormalised half vector:
// with cos^2 = (n.H)^2 / |H|^2 and sin^2 = |H_t|^2 / |H|^2, D = alpha^2 (|H|^2 / (alpha^2 (n.H)^2 + |H_t|^2))^2 / pi.
// The ratio is <= 1/alpha^2 (alpha <= 1), so D <= 1/(pi alpha^2) with no cancellation near h = n.
RTR_FN float brdfGgxD(vec3 n, vec3 H, float alpha) {
  float nH = dot(n, H);
  vec3 Ht = H - nH * n;
  float ht2 = dot(Ht, Ht);
  float a2 = alpha * alpha;
  float ratio = (nH * nH + ht2) / max(a2 * nH * nH + ht2, 1e-30f);
  float d = a2 * ratio * ratio / BRDF_PI;
  return nH > 0.0f ? d : 0.0f;
}

// Height-correlated Smith visibility V = G2 / (4 n.v n.l) (glTF Appendix B):
// V = 0.5 / (n.l sqrt((n.v)^2 (1 - a^2) + a^2) + n.v sqrt((n.l)^2 (1 - a^2) + a^2)); the denominator is
// >= alpha (n.v + n.l) and floored at BRDF_GGX_VDEN_MIN.
RTR_FN float brdfGgxVisibility(float nv, float nl, float alpha) {
  if (nv <= 0.0f || nl <= 0.0f) return 0.0f;
  float a2 = alpha * alpha;
  float lv = nl * sqrt(nv * nv * (1.0f - a2) + a2);
  float ll = nv * sqrt(nl * nl * (1.0f - a2) + a2);
  return 0.5f / max(lv + ll, BRDF_GGX_VDEN_MIN);
}

// All terms of BRDF `brdf` (BRDF_BECKMANN or BRDF_GGX) for unit v, l and any n. f = 0 for light below the
// shading hemisphere (n.l <= 0); for the view below it (back-facing interpolated normal) the specular is 0
// (G = 0 by (n.v)_+) but the Lambertian diffuse is kept, so silhouettes do not turn black.
// The diffuse: Beckmann (the brief) c/pi (1 - F)(1 - M) with the metal-tinted F; GGX (glTF Appendix B)
// c/pi (1 - F_dielectric)(1 - M), F_dielectric = 0.04 + 0.96 (1 - v.h)^5 (the spec's fresnel_mix of the
// dielectric, which metal has no diffuse to mix with). Both share F for the specular: the spec's metal
// and dielectric specular mixed by M is exactly D V F with F0 = mix(0.04, c, M).
RTR_FN BrdfTerms brdfTerms(int brdf, vec3 n, vec3 v, vec3 l, vec3 baseColor, float roughness, float metalness) {
  vec3 c = clamp(baseColor, vec3(0.0f), vec3(1.0f));
  float metal = clamp(metalness, 0.0f, 1.0f);
  vec3 nn = brdfSafeNormal(n);
  vec3 H = v + l;  // unnormalised half vector; h = H / |H|
  float hh = dot(H, H);
  float nH = dot(nn, H);
  float nv = dot(nn, v);
  float nl = dot(nn, l);
  float vh = 0.5f * sqrt(hh);  // v.h for unit v, l (exact, no division)

  BrdfTerms t;
  t.F = brdfFresnel(vh, c, metal);
  bool lit = nl > 0.0f;
  if (brdf == BRDF_GGX) {
    float alpha = brdfAlpha(roughness);
    float V = brdfGgxVisibility(nv, nl, alpha);
    t.D = brdfGgxD(nn, H, alpha);
    t.G = min(1.0f, 4.0f * max(nv, 0.0f) * max(nl, 0.0f) * V);
    float fd = brdfFresnel(vh, vec3(0.0f), 0.0f).x;  // the dielectric's Fresnel
    t.diffuse = lit ? c * ((1.0f / BRDF_PI) * (1.0f - fd) * (1.0f - metal)) : vec3(0.0f);
    t.specular = t.D * t.F * V;
    return t;
  }
  t.D = brdfBeckmannD(nn, H, brdfAlpha(roughness));
  t.G = brdfMaskingG(nv, nl, nH, hh);
  t.diffuse = lit ? c * (1.0f / BRDF_PI) * (vec3(1.0f) - t.F) * (1.0f - metal) : vec3(0.0f);
  t.specular = t.D * t.F * brdfVisibility(nv, nl, nH, hh);
  return t;
}

// What one light adds (brief eq. 1, its sum's term): (f_diffuse + f_spec) c_light (n.l)_+.
RTR_FN vec3 pbrDirect(int brdf, vec3 n, vec3 v, vec3 l, vec3 lightColor, vec3 baseColor, float roughness,
                      float metalness) {
  BrdfTerms t = brdfTerms(brdf, n, v, l, baseColor, roughness, metalness);
  float nl = max(dot(brdfSafeNormal(n), l), 0.0f);
  return (t.diffuse + t.specular) * lightColor * nl;
}

// Outgoing radiance for one point light (brief eq. 1):
// L = c_ambient c_mat + c_emit + (f_diffuse + f_spec) c_light (n.l)_+. More lights add more pbrDirect terms.
RTR_FN vec3 shadePbr(int brdf, vec3 n, vec3 v, vec3 l, vec3 lightColor, vec3 ambient, vec3 baseColor,
                     float roughness, float metalness, vec3 emissive) {
  vec3 c = clamp(baseColor, vec3(0.0f), vec3(1.0f));
  return ambient * c + emissive + pbrDirect(brdf, n, v, l, lightColor, baseColor, roughness, metalness);
}

// ---- Importance sampling of the BRDF (the tracer's Monte Carlo; docs/environment.md) ----
// A direction l is drawn from a mixture: with probability brdfSpecularChance a half vector h in
// proportion to D(h) (n.h) of the BRDF's own NDF, reflected about h (density D (n.h) / (4 v.h) per unit
// solid angle of l); otherwise the cosine-weighted hemisphere (density n.l / pi). brdfPdf is the
// mixture's density, which multiple importance sampling needs for directions drawn by anything else.
// Uniform numbers in [0, 1); 1 itself is clamped just below.

RTR_CONST float BRDF_U_MAX = 0.99999994f;  // the largest float below 1

// Luminance weights (Rec. 709), for the mixture's lobe probability.
RTR_FN float brdfLuminance(vec3 c) { return dot(c, vec3(0.2126f, 0.7152f, 0.0722f)); }

// A half vector about +z drawn in proportion to D(h) cos(theta_h). sin^2 and cos^2 are computed apart (no
// 1 - cos^2 cancellation), so alpha = 1e-3 keeps its narrow lobe:
//   Beckmann: tan^2 = -alpha^2 ln(1 - u), the inverse of its CDF 1 - exp(-tan^2 / alpha^2);
//   GGX:      cos^2 = (1 - u) / (1 + (alpha^2 - 1) u), sin^2 = alpha^2 u / (1 + (alpha^2 - 1) u).
RTR_FN vec3 brdfSampleHalfLocal(int brdf, vec2 u, float alpha) {
  float ux = min(max(u.x, 0.0f), BRDF_U_MAX);
  float a2 = alpha * alpha;
  float cos2;
  float sin2;
  if (brdf == BRDF_GGX) {
    float den = 1.0f + (a2 - 1.0f) * ux;  // >= alpha^2 > 0
    cos2 = (1.0f - ux) / den;
    sin2 = a2 * ux / den;
  } else {
    float t2 = -a2 * log(1.0f - ux);
    cos2 = 1.0f / (1.0f + t2);
    sin2 = t2 / (1.0f + t2);
  }
  float phi = 2.0f * BRDF_PI * u.y;
  float st = sqrt(max(sin2, 0.0f));
  return vec3(st * cos(phi), st * sin(phi), sqrt(max(cos2, 0.0f)));
}

// A cosine-weighted direction about +z (density cos(theta) / pi).
RTR_FN vec3 brdfSampleCosineLocal(vec2 u) {
  float ux = min(max(u.x, 0.0f), BRDF_U_MAX);
  float r = sqrt(ux);
  float phi = 2.0f * BRDF_PI * u.y;
  return vec3(r * cos(phi), r * sin(phi), sqrt(1.0f - ux));
}

// `local` (about +z) turned into the frame of unit n: a branch-free orthonormal basis that stays
// accurate for every n (Duff et al. 2017's construction).
RTR_FN vec3 brdfToFrame(vec3 local, vec3 n) {
  float sgn = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sgn + n.z);
  float b = n.x * n.y * a;
  vec3 t = vec3(1.0f + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
  vec3 bt = vec3(b, sgn + n.y * n.y * a, -n.y);
  return local.x * t + local.y * bt + local.z * n;
}

// The probability of drawing from the specular lobe: its Fresnel weight seen from v against the diffuse
// weight (about each lobe's share of the albedo, which keeps f cos / pdf nearly constant), 1 without a
// diffuse lobe (metal). View below the surface: the specular is 0, so 0.
RTR_FN float brdfSpecularChance(float nv, vec3 baseColor, float metalness) {
  vec3 c = clamp(baseColor, vec3(0.0f), vec3(1.0f));
  float metal = clamp(metalness, 0.0f, 1.0f);
  float diff = brdfLuminance(c) * (1.0f - metal);
  if (nv <= 0.0f) return diff > 0.0f ? 0.0f : 1.0f;
  if (!(diff > 0.0f)) return 1.0f;
  float spec = brdfLuminance(brdfFresnel(nv, c, metal));
  return spec / (spec + diff);
}

// Draws l for BRDF `brdf` at unit v and any n from three uniform numbers (u.x picks the lobe). The
// result is unit; it may lie below n (f = 0 there).
RTR_FN vec3 brdfSampleDirection(int brdf, vec3 n, vec3 v, vec3 u, vec3 baseColor, float roughness, float metalness) {
  vec3 nn = brdfSafeNormal(n);
  if (dot(nn, nn) == 0.0f) return v;  // zero normal: no light arrives, any direction will do
  float p = brdfSpecularChance(dot(nn, v), baseColor, metalness);
  if (u.x < p) {
    vec3 h = brdfToFrame(brdfSampleHalfLocal(brdf, vec2(u.y, u.z), brdfAlpha(roughness)), nn);
    return brdfSafeNormal(2.0f * dot(v, h) * h - v);
  }
  return brdfSafeNormal(brdfToFrame(brdfSampleCosineLocal(vec2(u.y, u.z)), nn));
}

// The density (per unit solid angle) brdfSampleDirection draws unit l with; 0 below the hemisphere of n,
// where f = 0. The specular part D (n.h) / (4 v.h) from H = v + l: n.h = n.H / |H|, v.h = |H| / 2, so
// D n.H / (2 |H|^2), |H|^2 floored as in the masking term.
RTR_FN float brdfPdf(int brdf, vec3 n, vec3 v, vec3 l, vec3 baseColor, float roughness, float metalness) {
  vec3 nn = brdfSafeNormal(n);
  float nl = dot(nn, l);
  if (!(nl > 0.0f)) return 0.0f;
  float p = brdfSpecularChance(dot(nn, v), baseColor, metalness);
  vec3 H = v + l;
  float hh = max(dot(H, H), BRDF_HH_MIN);
  float alpha = brdfAlpha(roughness);
  float D = brdf == BRDF_GGX ? brdfGgxD(nn, H, alpha) : brdfBeckmannD(nn, H, alpha);
  float spec = D * max(dot(nn, H), 0.0f) / (2.0f * hh);
  return p * spec + (1.0f - p) * nl * (1.0f / BRDF_PI);
}

// The brief's Beckmann BRDF without the selector (the form the renderer's shaders called before GGX).
RTR_FN BrdfTerms brdfTerms(vec3 n, vec3 v, vec3 l, vec3 baseColor, float roughness, float metalness) {
  return brdfTerms(BRDF_BECKMANN, n, v, l, baseColor, roughness, metalness);
}
RTR_FN vec3 pbrDirect(vec3 n, vec3 v, vec3 l, vec3 lightColor, vec3 baseColor, float roughness, float metalness) {
  return pbrDirect(BRDF_BECKMANN, n, v, l, lightColor, baseColor, roughness, metalness);
}
RTR_FN vec3 shadePbr(vec3 n, vec3 v, vec3 l, vec3 lightColor, vec3 ambient, vec3 baseColor, float roughness,
                     float metalness, vec3 emissive) {
  return shadePbr(BRDF_BECKMANN, n, v, l, lightColor, ambient, baseColor, roughness, metalness, emissive);
}

#ifdef __cplusplus
}  // namespace rtr::shader
#endif

#endif
