#include "env_options.hpp"

#include "core/cli.hpp"

namespace rtr::cli {

void addEnvOptions(CLI::App& app, EnvOptions& o) {
  app.add_option("--env", o.env.source, "light from an environment: an equirectangular .hdr or .exr file | sky (a "
                 "generated daylight sky with a sun) | none (docs/environment.md)")->capture_default_str();
  app.add_option("--env-intensity", o.env.intensity, "multiplies the environment's radiance")
      ->capture_default_str()->check(number(0, 1e30));
  app.add_option("--env-rotation", o.env.rotationDeg, "turns the environment about +y, degrees")
      ->capture_default_str()->check(number(-36000, 36000));
  app.add_option("--env-blur", o.blur, "the backdrop's environment: 0 sharp, up to 1 as blurred as the roughest "
                 "prefiltered level")->capture_default_str()->check(number(0, 1));
  app.add_option("--background", o.background, "linear colour r,g,b (or one grey value) of pixels no surface covers "
                 "(default: 0.18, mid grey); with --env it replaces the environment there")
      ->check(checked([](const std::string& t) { parseColor("--background", t, true); }, "R,G,B"));
}

Backdrop backdrop(const EnvOptions& o) {
  Backdrop b;
  if (!o.background.empty()) b.color = parseColor("--background", o.background, true);
  if (hasEnvironment(o) && o.background.empty()) b.blur = o.blur;
  return b;
}

}  // namespace rtr::cli
