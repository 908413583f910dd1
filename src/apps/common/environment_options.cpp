#include "apps/common/environment_options.hpp"

#include "core/cli.hpp"

namespace rtr::cli {

void addEnvironmentOptions(CLI::App& app, EnvironmentOptions& o, bool blur) {
  app.add_option("--env", o.settings.source,
                 "environment light: an equirectangular .hdr or .exr file, 'sky' (a "
                 "generated daylight sky with a sun) or 'none' (docs/environment.md)")
      ->capture_default_str();
  app.add_option("--env-intensity", o.settings.intensity, "multiplies the environment's radiance")
      ->capture_default_str()
      ->check(number(0, 1e30));
  app.add_option("--env-rotation", o.settings.rotationDeg, "turns the environment about +y, degrees")
      ->capture_default_str()
      ->check(number(-1e6, 1e6));
  if (blur)
    app.add_option("--env-blur", o.blur,
                   "the backdrop's environment: 0 sharp, up to 1 as blurred as the roughest "
                   "prefiltered level")
        ->capture_default_str()
        ->check(number(0, 1));
  app.add_option("--background", o.background,
                 "linear colour r,g,b (or one grey value) that camera rays missing the "
                 "scene see (default: the environment, else a mid-grey 0.18)")
      ->check(checked([](const std::string& t) { parseColor("--background", t, true); }, "R,G,B"));
}

void EnvironmentOptions::resolve() {
  showEnvironment = hasEnvironment() && background.empty();
  backgroundColor = background.empty() ? glm::vec3(kDefaultBackground) : parseColor("--background", background, true);
}

}  // namespace rtr::cli
