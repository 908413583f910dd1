#pragma once
// The light options of both renderers' command lines (rtr-view, rtr-trace; docs/lights.md), defined once.
#include <CLI/CLI.hpp>

#include "scene/lights.hpp"

namespace rtr::cli {

// Adds --light X,Y,Z, --light-color R,G,B (with --light), --falloff, --ambient R,G,B and --no-default-light
// to `app`; parsing writes them into `options` (the values are checked first: a bad one is a usage error).
void addLightOptions(CLI::App& app, LightOptions& options);

}  // namespace rtr::cli
