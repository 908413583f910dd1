// CPU tests of the shared BRDF header (shaders/shared/brdf.h), compiled here as C++ with GLM.
#include "brdf.h"
#include "brdf_quadrature.hpp"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace rtr::shader {
namespace {

constexpr double kPi = 3.14159265358979323846;
const float kRoughness[] = {0.0f, 1e-4f, 0.01f, 0.1f, 0.5f, 1.0f};
const float kMetalness[] = {0.0f, 0.5f, 1.0f};

// Unit vector at polar angle theta from +z, azimuth phi, in double then rounded.
glm::vec3 dir(double theta, double phi) {
  return glm::vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

// Rotates +z onto unit n (any orthonormal frame will do).
glm::vec3 toFrame(glm::vec3 local, glm::vec3 n) {
  glm::vec3 a = std::fabs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  glm::vec3 t = glm::normalize(glm::cross(a, n));
  glm::vec3 b = glm::cross(n, t);
  return local.x * t + local.y * b + local.z * n;
}

bool finiteNonNeg(float x) { return std::isfinite(x) && x >= 0.0f; }
bool finiteNonNeg(glm::vec3 x) { return finiteNonNeg(x.x) && finiteNonNeg(x.y) && finiteNonNeg(x.z); }

// Classification of a cosine for the coverage check of the grid.
enum Cat { kNeg, kZero, kTiny, kGrazing, kNormal, kCats };
Cat classify(float c) {
  if (c < 0.0f) return kNeg;
  if (c == 0.0f) return kZero;
  if (c < 1e-5f) return kTiny;
  if (c < 2e-2f) return kGrazing;
  return kNormal;
}

TEST(Brdf, DenseGridIsFiniteAndNonNegative) {
  // Polar angles hit exactly 0, tiny, grazing, exactly 90 deg (n.x = cos(pi/2) in float ~ -4e-8) and below.
  const double half = kPi / 2;
  const double thetas[] = {0.0,         1e-7, 1e-3,        0.5,         1.2, half - 1e-2, half - 1e-4,
                           half - 1e-6, half, half + 1e-6, half + 1e-3, 2.5, kPi};
  const double phis[] = {0.0, 0.7, kPi / 2, kPi - 1e-6, kPi, 4.0};
  std::vector<glm::vec3> dirs;
  for (double t : thetas)
    for (double p : phis) dirs.push_back(dir(t, p));
  dirs.push_back(glm::vec3(1, 0, 0));  // exactly in the tangent plane
  dirs.push_back(glm::vec3(-1, 0, 0));

  const glm::vec3 normals[] = {glm::vec3(0, 0, 1),     glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f)),
                               glm::vec3(0, 0, 1e-3f), glm::vec3(0, 0, 1e-20f),
                               glm::vec3(0),           glm::vec3(0, 0, -1)};
  const glm::vec3 base(0.9f, 0.5f, 0.1f), light(1.0f), ambient(0.02f), emissive(0.0f);

  int cover[4][kCats] = {};  // n.l, n.v, n.h, v.h
  long evaluated = 0;
  for (glm::vec3 n : normals) {
    glm::vec3 un = glm::length(n) > 0.5f ? n : glm::vec3(0, 0, 1);  // frame for the directions
    for (size_t i = 0; i < dirs.size(); ++i) {
      glm::vec3 v = toFrame(dirs[i], un);
      for (size_t j = 0; j < dirs.size() + 2; ++j) {
        // The two extra l's: exactly opposite v, and opposite v up to 1e-6 (the v.h -> 0 corner).
        glm::vec3 l = j < dirs.size()    ? toFrame(dirs[j], un)
                      : j == dirs.size() ? -v
                                         : glm::normalize(-v + 1e-6f * toFrame(glm::vec3(0, 0, 1), un));
        if (n == normals[0]) {
          glm::vec3 H = v + l;
          float hl = glm::length(H);
          glm::vec3 h = hl > 0 ? H / hl : glm::vec3(0);
          cover[0][classify(glm::dot(n, l))]++;
          cover[1][classify(glm::dot(n, v))]++;
          cover[2][classify(glm::dot(n, h))]++;
          cover[3][classify(glm::dot(v, h))]++;
        }
        for (float r : kRoughness)
          for (float m : kMetalness)
            for (int brdf : {BRDF_BECKMANN, BRDF_GGX}) {
              BrdfTerms t = brdfTerms(brdf, n, v, l, base, r, m);
              glm::vec3 L = shadePbr(brdf, n, v, l, light, ambient, base, r, m, emissive);
              ++evaluated;
              ASSERT_TRUE(finiteNonNeg(t.D) && finiteNonNeg(t.F) && finiteNonNeg(t.G) && finiteNonNeg(t.diffuse) &&
                          finiteNonNeg(t.specular) && finiteNonNeg(L))
                  << "n " << n.x << ' ' << n.y << ' ' << n.z << " v " << v.x << ' ' << v.y << ' ' << v.z << " l " << l.x << ' '
                  << l.y << ' ' << l.z << " r " << r << " m " << m << " brdf " << brdf << ": D " << t.D << " G " << t.G
                  << " spec " << t.specular.x << " L " << L.x;
              ASSERT_LE(t.G, 1.0f);
              ASSERT_LE(t.F.x, 1.0f);
              // The sampling side on the same grid: the density of any l, and draws at extreme numbers.
              const float pdf = brdfPdf(brdf, n, v, l, base, r, m);
              ASSERT_TRUE(finiteNonNeg(pdf)) << "pdf " << pdf << " r " << r << " m " << m << " brdf " << brdf;
              if (j == 0)
                for (float u0 : {0.0f, 0.3f, 0.9f})
                  for (float u1 : {0.0f, 1e-7f, 0.5f, BRDF_U_MAX, 1.0f}) {
                    const glm::vec3 d = brdfSampleDirection(brdf, n, v, glm::vec3(u0, u1, 1.0f - u1), base, r, m);
                    ASSERT_TRUE(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z));
                    ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f) << "r " << r << " m " << m << " u " << u0 << ' ' << u1;
                    ASSERT_TRUE(finiteNonNeg(brdfPdf(brdf, n, v, d, base, r, m)));
                  }
            }
      }
    }
  }
  // The sweep must really reach every regime (else the test proves less than it claims).
  // v.h is never negative by construction (h bisects v and l), so skip that cell.
  for (int q = 0; q < 4; ++q)
    for (int c = 0; c < kCats; ++c) {
      if (q == 3 && c == kNeg) continue;
      EXPECT_GT(cover[q][c], 0) << "cosine " << q << " class " << c;
    }
  EXPECT_GT(evaluated, 200000);
}

// The brief's formulas, evaluated as written in double precision; only valid away from the edge cases.
struct Ref {
  double D, G, F[3], diffuse[3], specular[3], L[3];
};
Ref reference(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, glm::dvec3 c, double rough, double metal, glm::dvec3 light,
              glm::dvec3 ambient, glm::dvec3 emit) {
  Ref r{};
  // Normalise in double: a float "unit" n is off by ~5e-8, which 1 - (n.h)^2 over alpha^2 amplifies.
  n = glm::normalize(n), v = glm::normalize(v), l = glm::normalize(l);
  glm::dvec3 h = glm::normalize(v + l);
  double nh = glm::dot(n, h), nv = glm::dot(n, v), nl = glm::dot(n, l), vh = glm::dot(v, h);
  double a = rough * rough;
  r.D = std::exp((nh * nh - 1) / (a * a * nh * nh)) / (kPi * a * a * nh * nh * nh * nh);
  r.G = std::min(1.0, std::min(2 * nh * nv / vh, 2 * nh * nl / vh));
  for (int k = 0; k < 3; ++k) {
    double F0 = (1 - metal) * 0.04 + metal * c[k];
    r.F[k] = F0 + (1 - F0) * std::pow(1 - vh, 5);
    r.diffuse[k] = c[k] / kPi * (1 - r.F[k]) * (1 - metal);
    r.specular[k] = r.D * r.F[k] * r.G / (4 * nv * nl);
    r.L[k] = ambient[k] * c[k] + emit[k] + (r.diffuse[k] + r.specular[k]) * light[k] * nl;
  }
  return r;
}

TEST(Brdf, MatchesStraightforwardFormulasAtOrdinaryAngles) {
  const glm::vec3 n = glm::normalize(glm::vec3(0.2f, 0.1f, 1.0f));
  const glm::vec3 light(1.0f, 0.9f, 0.8f), ambient(0.02f, 0.03f, 0.04f), emit(0.1f, 0.0f, 0.2f);
  const glm::vec3 base(0.8f, 0.4f, 0.15f);
  double worst = 0;
  int checked = 0;
  for (float rough : {0.2f, 0.35f, 0.5f, 0.75f, 1.0f})
    for (float metal : {0.0f, 0.3f, 1.0f})
      for (double tv : {0.1, 0.6, 1.1, 1.4})
        for (double tl : {0.2, 0.7, 1.0, 1.3})
          for (double dphi : {0.3, 1.5, 2.6, kPi}) {
            glm::vec3 v = toFrame(dir(tv, 0.4), n), l = toFrame(dir(tl, 0.4 + dphi), n);
            Ref r = reference(n, v, l, base, rough, metal, light, ambient, emit);
            // Skip far lobe tails (D below 1e-3 of its peak): float carries exp(-x) only to ~x * 1e-7.
            double a = double(rough) * rough;
            if (r.D < 1e-3 / (kPi * a * a)) continue;
            BrdfTerms t = brdfTerms(n, v, l, base, rough, metal);
            glm::vec3 L = shadePbr(n, v, l, light, ambient, base, rough, metal, emit);
            auto rel = [&](double got, double want) {
              double e = std::fabs(got - want) / std::max(std::fabs(want), 1e-12);
              worst = std::max(worst, e);
              return e;
            };
            EXPECT_LT(rel(t.D, r.D), 1e-5);
            EXPECT_LT(rel(t.G, r.G), 1e-5);
            for (int k = 0; k < 3; ++k) {
              EXPECT_LT(rel(t.F[k], r.F[k]), 1e-5);
              if (metal < 1.0f) { EXPECT_LT(rel(t.diffuse[k], r.diffuse[k]), 1e-5); }
              EXPECT_LT(rel(t.specular[k], r.specular[k]), 1e-5);
              EXPECT_LT(rel(L[k], r.L[k]), 1e-5);
            }
            ++checked;
          }
  EXPECT_GT(checked, 500);
  RecordProperty("worst_relative_error", std::to_string(worst));
}

// Integrates over half vectors h = (theta, phi) with tan(theta) = alpha * s, s in [0, 8] (exp(-64) of
// the Beckmann mass left out), so the same grid resolves alpha = 1e-3 and alpha = 1.
template <class F>
double integrateOverH(double alpha, int ns, int nphi, F integrand) {
  const double smax = 8.0;
  double sum = 0;
  for (int i = 0; i < ns; ++i) {
    double s = (i + 0.5) * smax / ns;
    double theta = std::atan(alpha * s);
    double dtheta = alpha / (1 + alpha * alpha * s * s) * (smax / ns);
    for (int j = 0; j < nphi; ++j) {
      double phi = (j + 0.5) * 2 * kPi / nphi;
      glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      sum += integrand(h) * std::sin(theta) * dtheta * (2 * kPi / nphi);
    }
  }
  return sum;
}

TEST(Brdf, BeckmannIntegratesToOneOverTheProjectedHemisphere) {
  const glm::vec3 n(0, 0, 1);
  for (float rough : kRoughness) {
    double alpha = brdfAlpha(rough);
    auto projectedD = [&](glm::dvec3 h) {
      glm::vec3 hf(h);
      return double(brdfTerms(n, hf, hf, glm::vec3(0.5f), rough, 0.0f).D) * h.z;  // v = l = h
    };
    double coarse = integrateOverH(alpha, 1000, 4, projectedD);
    double fine = integrateOverH(alpha, 2000, 4, projectedD);
    double err = std::fabs(fine - coarse) + 2e-6;  // midpoint-rule estimate + float evaluation of D
    EXPECT_NEAR(fine, 1.0, 3 * err) << "roughness " << rough;
  }
}

TEST(Brdf, SpecularAlbedoWithoutFresnelIsAtMostOne) {
  const glm::vec3 n(0, 0, 1);
  const double viewAngles[] = {0.0, 0.5, 1.0, 1.3, 1.5, 1.56, kPi / 2 - 1e-3};
  for (float rough : kRoughness) {
    double alpha = brdfAlpha(rough);
    for (double tv : viewAngles) {
      glm::dvec3 v(std::sin(tv), 0, std::cos(tv));
      // F = 1 (white metal): f = D G / (4 n.v n.l); dω_l = 4 (v.h) dω_h for the h with v.h > 0.
      auto integrand = [&](glm::dvec3 h) {
        double vh = glm::dot(v, h);
        if (vh <= 0) return 0.0;
        glm::dvec3 l = 2 * vh * h - v;
        BrdfTerms t = brdfTerms(n, glm::vec3(v), glm::vec3(l), glm::vec3(1.0f), rough, 1.0f);
        return double(t.specular.x) * std::max(l.z, 0.0) * 4 * vh;
      };
      double coarse = integrateOverH(alpha, 150, 128, integrand);
      double fine = integrateOverH(alpha, 300, 256, integrand);
      double err = std::fabs(fine - coarse) + 1e-4;
      EXPECT_LE(fine, 1.0 + 3 * err) << "roughness " << rough << " view angle " << tv << " coarse " << coarse;
      EXPECT_GT(fine, 0.0);
    }
  }
}

TEST(Brdf, TinyAlphaKeepsPrecisionNearTheMirrorDirection) {
  // At alpha = 1e-3 the exponent -tan^2/alpha^2 needs tan^2 to ~1e-9 absolute; 1 - (n.h)^2 in float has
  // ~1e-7 absolute error (a 10 % error in D), the tangential form keeps it to ~1e-4.
  const glm::vec3 n(0, 0, 1);
  const double alpha = BRDF_ALPHA_MIN;
  for (double s : {0.3, 1.0, 2.0}) {
    double theta = std::atan(alpha * s);
    glm::vec3 h = dir(theta, 0.3);
    double hx = h.x, hy = h.y, hz = h.z;
    double tan2 = (hx * hx + hy * hy) / (hz * hz);  // exact for the float h actually passed
    double want = std::exp(-tan2 / (alpha * alpha)) * (1 + tan2) * (1 + tan2) / (kPi * alpha * alpha);
    float got = brdfTerms(n, h, h, glm::vec3(1), 0.0f, 0.0f).D;
    EXPECT_NEAR(got / want, 1.0, 1e-3) << "s " << s;
  }
}

TEST(Brdf, RoughnessZeroGivesTheClampedFiniteHighlight) {
  const glm::vec3 n(0, 0, 1), v = dir(0.4, 0.0), l = dir(0.4, kPi);  // mirror configuration, h = n
  BrdfTerms t = brdfTerms(n, v, l, glm::vec3(1), 0.0f, 1.0f);
  EXPECT_NEAR(t.D, 1.0 / (kPi * BRDF_ALPHA_MIN * BRDF_ALPHA_MIN), 1.0);
  EXPECT_FLOAT_EQ(t.D, brdfTerms(n, v, l, glm::vec3(1), 1e-4f, 1.0f).D);  // below the clamp: identical
  // Off the mirror direction by 1 degree the highlight is gone.
  EXPECT_LT(brdfTerms(n, v, dir(0.4 + 0.0175, kPi), glm::vec3(1), 0.0f, 1.0f).D, 1e-20f);
}

TEST(Brdf, DegenerateNormalsAndHemispheres) {
  const glm::vec3 v = dir(0.3, 0.0), l = dir(0.5, 2.0), base(0.6f, 0.5f, 0.4f), amb(0.1f), emit(0.05f, 0, 0);
  // Zero normal: no direct light, only ambient and emissive.
  glm::vec3 L = shadePbr(glm::vec3(0), v, l, glm::vec3(5), amb, base, 0.5f, 0.0f, emit);
  EXPECT_EQ(L, amb * base + emit);
  // Unnormalised normal shades like the normalised one.
  glm::vec3 a = shadePbr(glm::vec3(0, 0, 7), v, l, glm::vec3(1), amb, base, 0.5f, 0.0f, emit);
  glm::vec3 b = shadePbr(glm::vec3(0, 0, 1), v, l, glm::vec3(1), amb, base, 0.5f, 0.0f, emit);
  EXPECT_NEAR(a.x, b.x, 1e-6f);
  // View below the shading normal: no specular, the diffuse stays.
  BrdfTerms back = brdfTerms(glm::vec3(0, 0, 1), dir(1.7, 0.0), l, base, 0.5f, 0.0f);
  EXPECT_EQ(back.specular, glm::vec3(0));
  EXPECT_GT(back.diffuse.x, 0.0f);
  // Light below: f = 0.
  BrdfTerms below = brdfTerms(glm::vec3(0, 0, 1), v, dir(1.7, 2.0), base, 0.5f, 0.0f);
  EXPECT_EQ(below.diffuse, glm::vec3(0));
  EXPECT_EQ(below.specular, glm::vec3(0));
}

TEST(Brdf, RadianceGoesToZeroAsTheLightReachesTheHorizon) {
  // The cancelled G/(4 n.v n.l) keeps f finite, and f (n.l) -> 0: no flash at the terminator.
  const glm::vec3 n(0, 0, 1), v = dir(1.0, 0.0);
  float prev = 1e30f;
  for (double eps : {1e-1, 1e-2, 1e-3, 1e-5, 1e-7}) {
    glm::vec3 L = shadePbr(n, v, dir(kPi / 2 - eps, kPi), glm::vec3(1), glm::vec3(0), glm::vec3(1), 0.3f, 1.0f, glm::vec3(0));
    EXPECT_LT(L.x, prev);
    prev = L.x;
  }
  EXPECT_LT(prev, 1e-4f);
}

// glTF 2.0 Appendix B as written, in double: D_GGX, the height-correlated V, and the metal-rough mix
// material = mix(dielectric_brdf, metal_brdf, metallic) with its Fresnel mixes.
Ref gltfReference(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, glm::dvec3 c, double rough, double metal, glm::dvec3 light,
                  glm::dvec3 ambient, glm::dvec3 emit) {
  Ref r{};
  n = glm::normalize(n), v = glm::normalize(v), l = glm::normalize(l);
  glm::dvec3 h = glm::normalize(v + l);
  double nh = glm::dot(n, h), nv = glm::dot(n, v), nl = glm::dot(n, l), vh = glm::dot(v, h);
  double a2 = rough * rough * rough * rough;
  double q = nh * nh * (a2 - 1) + 1;
  r.D = a2 / (kPi * q * q);
  double V = 0.5 / (nl * std::sqrt(nv * nv * (1 - a2) + a2) + nv * std::sqrt(nl * nl * (1 - a2) + a2));
  r.G = 4 * nv * nl * V;
  double x5 = std::pow(1 - vh, 5);
  for (int k = 0; k < 3; ++k) {
    double specular = V * r.D;
    double metalBrdf = specular * (c[k] + (1 - c[k]) * x5);
    double fd = 0.04 + 0.96 * x5;
    double dielectric = (1 - fd) * c[k] / kPi + fd * specular;
    r.diffuse[k] = (1 - metal) * (1 - fd) * c[k] / kPi;
    r.specular[k] = (1 - metal) * fd * specular + metal * metalBrdf;
    r.F[k] = r.specular[k] / specular;
    r.L[k] = ambient[k] * c[k] + emit[k] + ((1 - metal) * dielectric + metal * metalBrdf) * light[k] * nl;
  }
  return r;
}

TEST(BrdfGgx, MatchesTheGltfSpecAtOrdinaryAngles) {
  const glm::vec3 n = glm::normalize(glm::vec3(0.2f, 0.1f, 1.0f));
  const glm::vec3 light(1.0f, 0.9f, 0.8f), ambient(0.02f, 0.03f, 0.04f), emit(0.1f, 0.0f, 0.2f);
  const glm::vec3 base(0.8f, 0.4f, 0.15f);
  int checked = 0;
  for (float rough : {0.05f, 0.2f, 0.35f, 0.5f, 0.75f, 1.0f})
    for (float metal : {0.0f, 0.3f, 1.0f})
      for (double tv : {0.1, 0.6, 1.1, 1.4})
        for (double tl : {0.2, 0.7, 1.0, 1.3})
          for (double dphi : {0.3, 1.5, 2.6, kPi}) {
            glm::vec3 v = toFrame(dir(tv, 0.4), n), l = toFrame(dir(tl, 0.4 + dphi), n);
            Ref r = gltfReference(n, v, l, base, rough, metal, light, ambient, emit);
            BrdfTerms t = brdfTerms(BRDF_GGX, n, v, l, base, rough, metal);
            glm::vec3 L = shadePbr(BRDF_GGX, n, v, l, light, ambient, base, rough, metal, emit);
            // Float cosines carry ~1e-7 absolute error, which D amplifies by ~1/alpha^2 near its peak.
            const double tol = 1e-5 + 4e-7 / std::pow(double(rough), 4);
            auto rel = [](double got, double want) { return std::fabs(got - want) / std::max(std::fabs(want), 1e-12); };
            EXPECT_LT(rel(t.D, r.D), tol) << rough << ' ' << tv << ' ' << tl << ' ' << dphi;
            EXPECT_LT(rel(t.G, r.G), 1e-5);
            for (int k = 0; k < 3; ++k) {
              EXPECT_LT(rel(t.F[k], r.F[k]), 1e-5);
              if (metal < 1.0f) { EXPECT_LT(rel(t.diffuse[k], r.diffuse[k]), 1e-5); }
              EXPECT_LT(rel(t.specular[k], r.specular[k]), tol);
              EXPECT_LT(rel(L[k], r.L[k]), tol);
            }
            ++checked;
          }
  EXPECT_EQ(checked, 6 * 3 * 4 * 4 * 4);
}

// Integrates over half vectors with tan(theta) = alpha tan(psi), psi in [0, pi/2): GGX's long tail is
// covered to the horizon, and the same grid resolves alpha = 1e-3 and alpha = 1.
template <class F>
double integrateOverHGgx(double alpha, int npsi, int nphi, F integrand) {
  double sum = 0;
  for (int i = 0; i < npsi; ++i) {
    double psi = (i + 0.5) * (kPi / 2) / npsi;
    double tp = std::tan(psi);
    double theta = std::atan(alpha * tp);
    double dtheta = alpha * (1 + tp * tp) / (1 + alpha * alpha * tp * tp) * (kPi / 2) / npsi;
    for (int j = 0; j < nphi; ++j) {
      double phi = (j + 0.5) * 2 * kPi / nphi;
      glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      sum += integrand(h) * std::sin(theta) * dtheta * (2 * kPi / nphi);
    }
  }
  return sum;
}

TEST(BrdfGgx, DIntegratesToOneOverTheProjectedHemisphere) {
  const glm::vec3 n(0, 0, 1);
  for (float rough : kRoughness) {
    double alpha = brdfAlpha(rough);
    auto projectedD = [&](glm::dvec3 h) {
      glm::vec3 hf(h);
      return double(brdfTerms(BRDF_GGX, n, hf, hf, glm::vec3(0.5f), rough, 0.0f).D) * h.z;  // v = l = h
    };
    double coarse = integrateOverHGgx(alpha, 1000, 4, projectedD);
    double fine = integrateOverHGgx(alpha, 2000, 4, projectedD);
    double err = std::fabs(fine - coarse) + 2e-6;
    EXPECT_NEAR(fine, 1.0, 3 * err) << "roughness " << rough;
  }
}

TEST(BrdfGgx, SpecularAlbedoWithoutFresnelIsAtMostOne) {
  const glm::vec3 n(0, 0, 1);
  const double viewAngles[] = {0.0, 0.5, 1.0, 1.3, 1.5, 1.56, kPi / 2 - 1e-3};
  for (float rough : kRoughness) {
    double alpha = brdfAlpha(rough);
    for (double tv : viewAngles) {
      glm::dvec3 v(std::sin(tv), 0, std::cos(tv));
      auto integrand = [&](glm::dvec3 h) {
        double vh = glm::dot(v, h);
        if (vh <= 0) return 0.0;
        glm::dvec3 l = 2 * vh * h - v;
        BrdfTerms t = brdfTerms(BRDF_GGX, n, glm::vec3(v), glm::vec3(l), glm::vec3(1.0f), rough, 1.0f);
        return double(t.specular.x) * std::max(l.z, 0.0) * 4 * vh;
      };
      double coarse = integrateOverHGgx(alpha, 150, 128, integrand);
      double fine = integrateOverHGgx(alpha, 300, 256, integrand);
      double err = std::fabs(fine - coarse) + 1e-4;
      EXPECT_LE(fine, 1.0 + 3 * err) << "roughness " << rough << " view angle " << tv;
      // Smooth surfaces seen from above keep nearly all energy; rough ones lose some (single scattering).
      EXPECT_GT(fine, rough <= 0.1f && tv < 1.4 ? 0.98 : 0.25) << "roughness " << rough << " view angle " << tv;
    }
  }
}

TEST(BrdfGgx, HardCasesStayFiniteAndHemispheresBehave) {
  const glm::vec3 n(0, 0, 1);
  // Roughness 0: the clamped alpha's finite peak, 1/(pi alpha^2), at h = n.
  const glm::vec3 v = dir(0.4, 0.0), l = dir(0.4, kPi);
  EXPECT_NEAR(brdfTerms(BRDF_GGX, n, v, l, glm::vec3(1), 0.0f, 1.0f).D, 1.0 / (kPi * BRDF_ALPHA_MIN * BRDF_ALPHA_MIN), 1.0);
  // Zero normal: ambient and emission only.
  const glm::vec3 base(0.6f, 0.5f, 0.4f), amb(0.1f), emit(0.05f, 0, 0);
  EXPECT_EQ(shadePbr(BRDF_GGX, glm::vec3(0), v, dir(0.5, 2.0), glm::vec3(5), amb, base, 0.5f, 0.0f, emit), amb * base + emit);
  // View below: no specular, diffuse kept; light below: nothing.
  BrdfTerms back = brdfTerms(BRDF_GGX, n, dir(1.7, 0.0), dir(0.5, 2.0), base, 0.5f, 0.0f);
  EXPECT_EQ(back.specular, glm::vec3(0));
  EXPECT_GT(back.diffuse.x, 0.0f);
  BrdfTerms below = brdfTerms(BRDF_GGX, n, v, dir(1.7, 2.0), base, 0.5f, 0.0f);
  EXPECT_EQ(below.diffuse + below.specular, glm::vec3(0));
  // The light reaching the horizon: the radiance goes to zero, no flash at the terminator.
  float prev = 1e30f;
  for (double eps : {1e-1, 1e-2, 1e-3, 1e-5, 1e-7}) {
    glm::vec3 L = shadePbr(BRDF_GGX, n, dir(1.0, 0.0), dir(kPi / 2 - eps, kPi), glm::vec3(1), glm::vec3(0), glm::vec3(1), 0.3f,
                           1.0f, glm::vec3(0));
    EXPECT_LT(L.x, prev);
    prev = L.x;
  }
  EXPECT_LT(prev, 1e-4f);
  // Both grazing and opposite (v = -l up to 1e-6): finite.
  const glm::vec3 g = dir(kPi / 2 - 1e-7, 0.0);
  const BrdfTerms t = brdfTerms(BRDF_GGX, n, g, glm::normalize(-g + glm::vec3(0, 1e-6f, 0)), glm::vec3(1), 1.0f, 1.0f);
  EXPECT_TRUE(finiteNonNeg(t.specular) && finiteNonNeg(t.D));
}

// The selector: Beckmann is the brief's, unchanged by the form without it; GGX differs where it should.
TEST(BrdfGgx, SelectorPicksTheModel) {
  const glm::vec3 n(0, 0, 1), v = dir(0.3, 0.0), l = dir(0.6, 2.5), c(0.7f, 0.5f, 0.3f);
  const BrdfTerms a = brdfTerms(n, v, l, c, 0.4f, 0.3f), b = brdfTerms(BRDF_BECKMANN, n, v, l, c, 0.4f, 0.3f);
  EXPECT_EQ(a.D, b.D);
  EXPECT_EQ(a.specular, b.specular);
  const BrdfTerms g = brdfTerms(BRDF_GGX, n, v, l, c, 0.4f, 0.3f);
  EXPECT_NE(g.D, a.D);
  EXPECT_EQ(g.F, a.F);              // one Fresnel
  EXPECT_NE(g.diffuse, a.diffuse);  // glTF weights the diffuse by the dielectric's Fresnel
}

}  // namespace
}  // namespace rtr::shader

namespace rtr::shader {
namespace {

// Importance sampling (brdfSampleDirection / brdfPdf): the estimator f cos / pdf over its own draws
// gives the directional albedo found by quadrature, within four standard errors: this holds only if
// brdfPdf is the density the draws really have, on every lobe and roughness down to the clamped alpha.
TEST(BrdfSampling, EstimatorGivesTheDirectionalAlbedo) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const glm::vec3 n(0, 0, 1), base(0.9f, 0.6f, 0.3f);
  int checked = 0;
  for (int brdf : {BRDF_BECKMANN, BRDF_GGX})
    for (float rough : {0.0f, 0.2f, 0.5f, 1.0f})
      for (float metal : {0.0f, 1.0f})
        for (double tv : {0.3, 1.2, 1.5}) {
          const glm::vec3 v(float(std::sin(tv)), 0.0f, float(std::cos(tv)));
          const quadrature::Estimate ref = quadrature::directionalAlbedo(brdf, tv, base, rough, metal);
          const int N = 100000;
          double sum = 0, sum2 = 0;
          for (int i = 0; i < N; ++i) {
            const glm::vec3 l = brdfSampleDirection(brdf, n, v, glm::vec3(uni(rng), uni(rng), uni(rng)), base, rough, metal);
            const float pdf = brdfPdf(brdf, n, v, l, base, rough, metal);
            if (!(pdf > 0.0f)) continue;
            const BrdfTerms t = brdfTerms(brdf, n, v, l, base, rough, metal);
            const double x = double(t.diffuse.x + t.specular.x) * std::max(l.z, 0.0f) / pdf;
            sum += x;
            sum2 += x * x;
          }
          const double mean = sum / N, se = std::sqrt(std::max(sum2 / N - mean * mean, 0.0) / N);
          EXPECT_NEAR(mean, ref.value, 4 * se + ref.error + 1e-4)
              << "brdf " << brdf << " roughness " << rough << " metal " << metal << " view " << tv << " se " << se;
          ++checked;
        }
  EXPECT_EQ(checked, 48);
}

// The draws fall into bins of the hemisphere as often as brdfPdf integrated over each bin says (a
// binomial count within 5 sigma), for rough lobes whose density a bin grid resolves.
TEST(BrdfSampling, DrawsFollowThePdf) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const glm::vec3 n(0, 0, 1), base(0.8f, 0.8f, 0.8f);
  constexpr int kT = 8, kP = 8, kSub = 24;
  for (int brdf : {BRDF_BECKMANN, BRDF_GGX})
    for (float rough : {0.5f, 1.0f})
      for (float metal : {0.0f, 1.0f}) {
        const glm::vec3 v(float(std::sin(0.8)), 0.0f, float(std::cos(0.8)));
        const int N = 200000;
        std::vector<int> count(kT * kP, 0);
        for (int i = 0; i < N; ++i) {
          const glm::vec3 l = brdfSampleDirection(brdf, n, v, glm::vec3(uni(rng), uni(rng), uni(rng)), base, rough, metal);
          if (l.z <= 0.0f) continue;
          const double th = std::acos(std::min(double(l.z), 1.0)), ph = std::atan2(double(l.y), double(l.x)) + kPi;
          count[std::min(int(th / (kPi / 2) * kT), kT - 1) * kP + std::min(int(ph / (2 * kPi) * kP), kP - 1)]++;
        }
        for (int bt = 0; bt < kT; ++bt)
          for (int bp = 0; bp < kP; ++bp) {
            double prob = 0;
            for (int a = 0; a < kSub; ++a)
              for (int b = 0; b < kSub; ++b) {
                const double th = (bt + (a + 0.5) / kSub) * (kPi / 2) / kT, ph = (bp + (b + 0.5) / kSub) * 2 * kPi / kP - kPi;
                const glm::vec3 l = dir(th, ph);
                prob += double(brdfPdf(brdf, n, v, l, base, rough, metal)) * std::sin(th) * (kPi / 2 / kT / kSub) *
                        (2 * kPi / kP / kSub);
              }
            const double expect = prob * N, sigma = std::sqrt(std::max(expect * (1 - prob), 1.0));
            EXPECT_NEAR(count[bt * kP + bp], expect, 5 * sigma + 0.01 * expect)
                << "brdf " << brdf << " roughness " << rough << " metal " << metal << " bin " << bt << ',' << bp;
          }
      }
}

}  // namespace
}  // namespace rtr::shader
