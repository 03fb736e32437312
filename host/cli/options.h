// options.h - the settings schema (settings/schema.h) as command-line options: every `raster render`
// option that is a render setting, and `raster batch`'s defaults, come from here.
#ifndef RASTER_CLI_OPTIONS_H
#define RASTER_CLI_OPTIONS_H

#include <functional>
#include <string>

#include "settings/schema.h"

namespace CLI {
class App;
}

namespace sr {

// The help line of a setting: its help, its values and its default.
std::string optionHelp(const Setting& setting);

// Adds one option per setting of the schema to `app` (--NAME VALUE; a flag for a Bool), each with
// optionHelp's text. A given value is checked by the schema (a bad one fails the parse with the
// schema's one-line message) and handed to `store` with its setting.
void addSettingOptions(CLI::App& app, std::function<void(const Setting&, const nlohmann::json&)> store);

// addSettingOptions storing into `options`.
void addSettingOptions(CLI::App& app, RenderOptions& options);

}  // namespace sr

#endif  // RASTER_CLI_OPTIONS_H
