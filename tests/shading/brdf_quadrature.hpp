#pragma once
// Deterministic quadrature of the shared BRDF (shaders/shared/brdf.h) for tests: the directional albedo
// ∫ f(v, l) (n.l)_+ dω_l, the specular part over half vectors on a grid that follows the lobe's width
// (tan θ_h = α tan ψ, ψ uniform in [0, π/2): resolves α = 1e-3 and α = 1 alike), the diffuse part over l.
// The answer a uniform environment of radiance 1 gives; the error estimate is |fine − coarse|.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "brdf.h"

namespace rtr::shader::quadrature {

struct Estimate {
  double value, error;
};

// Integrates g(h) dω_h over the upper hemisphere (n = +z), the grid dense where tan θ_h is α-scale.
template <class G>
double overHalfVectors(double alpha, int npsi, int nphi, G g) {
  const double pi = 3.14159265358979323846;
  double sum = 0;
  for (int i = 0; i < npsi; ++i) {
    const double psi = (i + 0.5) * (pi / 2) / npsi, tp = std::tan(psi);
    const double theta = std::atan(alpha * tp);
    const double dtheta = alpha * (1 + tp * tp) / (1 + alpha * alpha * tp * tp) * (pi / 2) / npsi;
    for (int j = 0; j < nphi; ++j) {
      const double phi = (j + 0.5) * 2 * pi / nphi;
      const glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      sum += g(h) * std::sin(theta) * dtheta * (2 * pi / nphi);
    }
  }
  return sum;
}

// Directional albedo of BRDF `brdf` at view angle theta_v (n = +z, v in the xz plane), the specular part
// times specScale.
inline Estimate directionalAlbedo(int brdf, double thetaV, glm::vec3 base, float rough, float metal, int channel = 0,
                                  double specScale = 1) {
  const double pi = 3.14159265358979323846;
  const glm::dvec3 v(std::sin(thetaV), 0, std::cos(thetaV));
  const glm::vec3 n(0, 0, 1);
  auto spec = [&](glm::dvec3 h) {  // dω_l = 4 (v.h) dω_h
    const double vh = glm::dot(v, h);
    if (vh <= 0) return 0.0;
    const glm::dvec3 l = 2 * vh * h - v;
    if (l.z <= 0) return 0.0;
    const BrdfTerms t = brdfTerms(brdf, n, glm::vec3(v), glm::vec3(glm::normalize(l)), base, rough, metal);
    return double(t.specular[channel]) * specScale * l.z * 4 * vh;
  };
  auto diffuse = [&](int nt, int np) {
    double sum = 0;
    for (int i = 0; i < nt; ++i) {
      const double th = (i + 0.5) * (pi / 2) / nt;
      for (int j = 0; j < np; ++j) {
        const double ph = (j + 0.5) * 2 * pi / np;
        const glm::dvec3 l(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
        const BrdfTerms t = brdfTerms(brdf, n, glm::vec3(v), glm::vec3(l), base, rough, metal);
        sum += double(t.diffuse[channel]) * l.z * std::sin(th) * (pi / 2 / nt) * (2 * pi / np);
      }
    }
    return sum;
  };
  const double alpha = brdfAlpha(rough);
  const double coarse = overHalfVectors(alpha, 200, 128, spec) + diffuse(64, 128);
  const double fine = overHalfVectors(alpha, 400, 256, spec) + diffuse(128, 256);
  return {fine, std::fabs(fine - coarse) + 1e-4};
}

// The same with GGX's multiple-scattering compensation (docs/environment.md): the specular part times
// 1 + F0 (1 / E - 1), E the white metal's albedo at theta_v, F0 = mix(0.04, base, metal); Beckmann as is.
inline Estimate compensatedAlbedo(int brdf, double thetaV, glm::vec3 base, float rough, float metal, int channel = 0) {
  if (brdf != BRDF_GGX) return directionalAlbedo(brdf, thetaV, base, rough, metal, channel);
  const double e = directionalAlbedo(brdf, thetaV, glm::vec3(1.0f), rough, 1.0f).value;
  const double f0 = 0.04 + (double(base[channel]) - 0.04) * metal;
  return directionalAlbedo(brdf, thetaV, base, rough, metal, channel, 1 + f0 * (1 / e - 1));
}

}  // namespace rtr::shader::quadrature
