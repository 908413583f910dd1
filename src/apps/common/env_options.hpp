#pragma once
// The environment and backdrop options, one definition for every tool that renders (docs/files-and-cli.md):
// --env FILE|sky|none, --env-intensity K, --env-rotation DEG, --env-blur R, --background R,G,B.
#include <string>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

#include "scene/environment.hpp"

namespace rtr::cli {

// A neutral backdrop on which a black model is visible: linear 0.18, a photographer's mid grey (sRGB 118).
inline constexpr float kDefaultBackground = 0.18f;

struct EnvOptions {
  EnvironmentSettings env;      // --env, --env-intensity, --env-rotation
  std::string background;       // --background as given (empty: none given)
  float blur = 0.0f;            // --env-blur
};

// Adds the options to `app`, their values checked at parse time (a bad one is a usage error, exit 2).
void addEnvOptions(CLI::App& app, EnvOptions& o);

// What pixels that no surface covers show: `color` (linear), or with an environment, the environment at
// `blur` (0 sharp, up to 1 the roughest prefiltered level); blur < 0: the colour even with an environment
// (--background given with --env).
struct Backdrop {
  glm::vec3 color{kDefaultBackground};
  float blur = -1.0f;
};
Backdrop backdrop(const EnvOptions& o);

// With an environment the flat ambient term would count its light twice: its default is then 0.
inline bool hasEnvironment(const EnvOptions& o) { return o.env.source != "none"; }

}  // namespace rtr::cli
