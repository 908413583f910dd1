#include "apps/common/light_options.hpp"

#include "core/cli.hpp"

namespace rtr::cli {

void addLightOptions(CLI::App& app, LightOptions& o) {
  CLI::Option* light = app.add_option_function<std::string>(
                              "--light", [&o](const std::string& t) { o.position = parseVec3("--light", t); },
                              "one point light at x,y,z instead of the scene's lights")
                           ->check(checked([](const std::string& t) { parseVec3("--light", t); }, "X,Y,Z"));
  app.add_option_function<std::string>(
         "--light-color", [&o](const std::string& t) { o.color = parseColor("--light-color", t); },
         "colour x intensity of --light, r,g,b")
      ->needs(light)
      ->check(checked([](const std::string& t) { parseColor("--light-color", t); }, "R,G,B"));
  app.add_flag("--falloff", o.falloff, "inverse-square falloff on every light (not the default headlight)");
  app.add_option_function<std::string>(
         "--ambient", [&o](const std::string& t) { o.ambient = parseColor("--ambient", t, true); },
         "ambient colour r,g,b (or one grey value)")
      ->default_str("0.02")
      ->check(checked([](const std::string& t) { parseColor("--ambient", t, true); }, "R,G,B"));
  app.add_flag_callback(
      "--no-default-light", [&o] { o.defaultLight = false; },
      "a scene without lights gets no headlight (only ambient and emission light it: the assignment's "
      "strict behaviour)");
}

}  // namespace rtr::cli
