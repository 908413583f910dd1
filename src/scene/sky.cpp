// The generated daylight sky (environment.hpp's makeSky): single scattering in a spherical atmosphere.
// Radiance towards the viewer along a view ray is the sun's light scattered once at each point of the ray
// (Rayleigh by air, Mie by haze, each thinning exponentially with height), dimmed on its way from the sun
// to the point and from the point to the viewer. The constants are measured properties of Earth's air at
// red, green and blue (680, 550, 440 nm); the result is linear radiance relative to the sun's irradiance.
#include <algorithm>
#include <cmath>

#include "core/parallel.hpp"
#include "scene/environment.hpp"
#include "environment.h"

namespace rtr {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kEarth = 6360e3, kTop = 6420e3;           // radii, metres
constexpr double kHeightR = 8000.0, kHeightM = 1200.0;     // scale heights of air and haze
const glm::dvec3 kRayleigh{5.802e-6, 13.558e-6, 33.1e-6};  // scattering = extinction, per metre at sea level
constexpr double kMieScatter = 3.996e-6, kMieExtinct = 4.40e-6, kMieG = 0.8;

// Distance along the unit ray (origin o) to where it leaves the sphere of radius r; -1 if it misses.
double exitDistance(const glm::dvec3& o, const glm::dvec3& d, double r) {
  const double b = glm::dot(o, d), c = glm::dot(o, o) - r * r;
  const double disc = b * b - c;
  if (disc < 0.0) return -1.0;
  return -b + std::sqrt(disc);
}

bool hitsGround(const glm::dvec3& o, const glm::dvec3& d) {
  const double b = glm::dot(o, d), c = glm::dot(o, o) - kEarth * kEarth;
  return b < 0.0 && b * b - c >= 0.0;
}

struct Optical {
  double rayleigh = 0.0, mie = 0.0;
};  // optical depths per unit coefficient

Optical depthAlong(const glm::dvec3& o, const glm::dvec3& d, double length, int steps) {
  Optical od;
  const double ds = length / steps;
  for (int i = 0; i < steps; ++i) {
    const double h = glm::length(o + d * ((i + 0.5) * ds)) - kEarth;
    od.rayleigh += std::exp(-h / kHeightR) * ds;
    od.mie += std::exp(-h / kHeightM) * ds;
  }
  return od;
}

glm::dvec3 transmittance(const Optical& od, double haze) {
  return glm::exp(-(kRayleigh * od.rayleigh + glm::dvec3(kMieExtinct * haze * od.mie)));
}

// Sky radiance (sun irradiance 1 at the top of the atmosphere) towards the viewer from direction d.
glm::dvec3 inscatter(const glm::dvec3& eye, const glm::dvec3& d, const glm::dvec3& sun, double haze) {
  constexpr int kSteps = 24, kLightSteps = 8;
  const double length = exitDistance(eye, d, kTop);
  const double ds = length / kSteps;
  const double mu = glm::dot(d, sun);
  const double phaseR = 3.0 / (16.0 * kPi) * (1.0 + mu * mu);
  const double g = kMieG;
  const double phaseM = (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5));
  glm::dvec3 sumR(0.0), sumM(0.0);
  Optical view;
  for (int i = 0; i < kSteps; ++i) {
    const glm::dvec3 p = eye + d * ((i + 0.5) * ds);
    const double h = glm::length(p) - kEarth;
    const double dr = std::exp(-h / kHeightR) * ds, dm = std::exp(-h / kHeightM) * ds;
    view.rayleigh += dr * 0.5;  // to the middle of this step
    view.mie += dm * 0.5;
    if (!hitsGround(p, sun)) {
      const Optical light = depthAlong(p, sun, exitDistance(p, sun, kTop), kLightSteps);
      const glm::dvec3 t = transmittance({view.rayleigh + light.rayleigh, view.mie + light.mie}, haze);
      sumR += t * dr;
      sumM += t * dm;
    }
    view.rayleigh += dr * 0.5;
    view.mie += dm * 0.5;
  }
  return sumR * kRayleigh * phaseR + sumM * (kMieScatter * haze * phaseM);
}

}  // namespace

glm::vec3 skySunDirection(const SkySettings& s) {
  const float el = s.sunElevationDeg * float(kPi) / 180.0f, az = s.sunAzimuthDeg * float(kPi) / 180.0f;
  return glm::normalize(glm::vec3(std::cos(el) * std::sin(az), std::sin(el), -std::cos(el) * std::cos(az)));
}

ImageF makeSky(const SkySettings& s) {
  const uint32_t w = std::max(s.width, 8u), h = std::max(s.height, 4u);
  ImageF img{w, h, std::vector<glm::vec4>(size_t(w) * h, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f))};
  const glm::dvec3 sun = glm::dvec3(skySunDirection(s));
  const glm::dvec3 eye{0.0, kEarth + 2.0, 0.0};
  const double haze = std::max(s.haze, 0.0f);
  const uint32_t upper = (h + 1) / 2;  // rows whose centre is above the horizon (or on it)

  // The upper hemisphere's rows on all cores; rows are independent.
  parallelFor(upper, threadCount(), [&](size_t y) {
    for (uint32_t x = 0; x < w; ++x) {
      glm::dvec3 d = glm::dvec3(shader::envUvToDir({(x + 0.5f) / w, (y + 0.5f) / h}, 0.0f));
      d.y = std::max(d.y, 1e-4);  // the row at the horizon looks along it
      img.at(x, uint32_t(y)) = glm::vec4(glm::vec3(inscatter(eye, glm::normalize(d), sun, haze)), 1.0f);
    }
  });

  // The sun: its irradiance after the atmosphere, put into the texel that holds its centre (the disk is
  // smaller than a texel at any usual size), so the map carries the sun's energy exactly.
  const double dPhi = 2.0 * kPi / w, dTheta = kPi / h;
  if (sun.y > 0.0) {
    const Optical od = depthAlong(eye, sun, exitDistance(eye, sun, kTop), 64);
    const glm::dvec3 e = transmittance(od, haze);
    const glm::vec2 uv = shader::envDirToUv(glm::vec3(sun), 0.0f);
    const uint32_t sx = std::min(uint32_t(uv.x * w), w - 1), sy = std::min(uint32_t(uv.y * h), h - 1);
    const double texelOmega = dPhi * dTheta * std::sin((sy + 0.5) / h * kPi);
    img.at(sx, sy) += glm::vec4(glm::vec3(e / texelOmega), 0.0f);
  }

  // Scale so that a horizontal white Lambertian surface under sky and sun has radiance 1 (irradiance pi).
  double irr = 0.0;
  for (uint32_t y = 0; y < upper; ++y) {
    const double theta = (y + 0.5) / h * kPi;
    const double w8 = std::max(std::cos(theta), 0.0) * std::sin(theta) * dPhi * dTheta;
    for (uint32_t x = 0; x < w; ++x) irr += double(glm::dot(glm::vec3(img.at(x, y)), glm::vec3(0.2126f, 0.7152f, 0.0722f))) * w8;
  }
  const float scale = irr > 0.0 ? float(kPi / irr) : 1.0f;
  // Below the horizon: grey ground of albedo 0.2 lit by the same light.
  const glm::vec4 ground(glm::vec3(0.2f), 1.0f);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      glm::vec4& p = img.at(x, y);
      p = y < upper ? glm::vec4(glm::vec3(p) * scale, 1.0f) : ground;
    }
  return img;
}

}  // namespace rtr
