// schema.h - every render setting declared once: its name, type, default, allowed values or range and
// one line of help. From this one table come the `raster render` options and their help, the batch
// manifest's keys and their checks, the viewer's `raster render` arguments, the settings echoed in
// --stats, `raster settings` (the reference docs/settings.md holds) and the public API's settings by name.
//
// A setting is named as on the command line without the dashes ("texture-filter"); manifests and the
// API spell it with underscores ("texture_filter"), and every look-up accepts both. Values travel as
// JSON (numbers, strings, booleans, arrays of three numbers) or as command-line text; either way they
// are checked here and only here (checkSettingValue), and setSetting stores only checked values.
//
// Adding a setting: one entry in schema.cpp's table (with its member of RenderOptions) and its use in
// the pipeline; every front end, the reference in docs/settings.md and the tests pick it up from the table.
#ifndef RASTER_SETTINGS_SCHEMA_H
#define RASTER_SETTINGS_SCHEMA_H

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "settings/render_settings.h"

namespace sr {

enum class SettingType {
    Uint,    // a whole number within [min, max], or one of `numbers` when that is not empty; "auto" too
             // where allowAuto
    Float,   // a finite number within [min, max], a multiple of `step` when step > 0
    Bool,    // true or false (a flag on the command line)
    Choice,  // one of the names of `choices`
    Vec3,    // three finite numbers: X,Y,Z on the command line, [x, y, z] in JSON
    Camera,  // a camera spec (parseCameraSpec)
    Model,   // a model transform spec (parseModelSpec)
};

struct SettingChoice {
    std::string name;
    uint32_t value;
};

struct Setting {
    std::string name;  // command-line name without the dashes; JSON and API names use '_' for '-'
    SettingType type = SettingType::Uint;
    std::string group;  // reference section: image, camera, shading, anti-aliasing, primitives, ...
    std::string help;   // one line, no trailing period
    std::vector<SettingChoice> choices;  // Choice: every allowed name, in the order the help lists them
    std::vector<uint32_t> numbers;       // Uint: the allowed values when only some are (msaa)
    double min = 0.0, max = 0.0;         // Uint, Float: inclusive range
    double step = 0.0;                   // Float: values are multiples of this (0: any)
    bool allowAuto = false;              // Uint: also "auto" (the default that depends on other settings)
    std::string defaultNote;             // what the default means, when the value alone does not say
    // The member it reads and writes; set receives only values checkSettingValue accepted.
    std::function<nlohmann::json(const RenderOptions&)> get;
    std::function<void(RenderOptions&, const nlohmann::json&)> set;

    // The JSON/API spelling of the name: dashes as underscores.
    std::string key() const;
};

// Every setting, in the order of the reference.
const std::vector<Setting>& settingsSchema();
// The setting named `name` (dashes or underscores), or nullptr.
const Setting* findSetting(const std::string& name);
// The setting named `name`; `name` must be in the table (front ends naming a setting in code).
const Setting& setting(const std::string& name);

// Checks `value` against the setting and returns it in its canonical JSON form (a Uint as an unsigned
// integer, a Float as a number, a Choice as its name, a Vec3 as an array). `label` names the setting in
// the one-line error ("--msaa" on the command line, "msaa" in a manifest).
Result<nlohmann::json> checkSettingValue(const Setting& setting, const nlohmann::json& value,
                                         const std::string& label);
// `error` with every `option` in its message (the camera and model parsers write --camera and --model)
// named `label` instead: each front end names a setting its own way.
Error relabelled(Error error, const std::string& option, const std::string& label);
// The same from command-line text ("4", "0.5", "1,0,0", "lambert"; a Bool takes true/false/1/0).
Result<nlohmann::json> parseSettingText(const Setting& setting, const std::string& text,
                                        const std::string& label);
// checkSettingValue, then stores the value.
Status setSetting(RenderOptions& options, const Setting& setting, const nlohmann::json& value,
                  const std::string& label);

// The value of one setting as JSON, and as the command line writes it.
nlohmann::json settingValue(const RenderOptions& options, const Setting& setting);
std::string settingText(const RenderOptions& options, const Setting& setting);
// The default of a setting (its value in a default RenderOptions), as the command line writes it.
std::string settingDefaultText(const Setting& setting);

// Every setting's value by its key: the --stats echo, the manifest's canonical form, the API's view.
nlohmann::json settingsJson(const RenderOptions& options);
// The `raster render` arguments that reproduce `options` (each setting that differs from that command's
// default, imageRenderOptions(), as --name value; Bools as a bare --name), in schema order.
std::string renderArguments(const RenderOptions& options);

// The checks that involve several settings or whole RenderSettings built in code (each value as
// checkSettingValue would, the tessellation level against its mode, the raster grid within
// MAX_FRAMEBUFFER_DIM and under 2^31 samples, the wireframe's depth bias). Labels are the command
// line's. The pipeline calls this on every frame (checkRenderInputs).
Status checkSettings(const RenderSettings& settings);

// Samples per pixel (ssaa^2 x msaa) an EXR of every sample (aov-samples: an id and a depth channel
// each) holds at most.
constexpr uint32_t kMaxAovSamples = 64;
// aov-samples where a frame goes to files (`raster render`, a batch job): an EXR to hold the samples
// (`hasAov`) and at most kMaxAovSamples of them per pixel. `samplesName` and `aovName` name the setting
// and the EXR output as the front end does ("--aov-samples", "--aov FILE"; "aov_samples", "'aov'").
Status checkAovSamples(const RenderSettings& settings, bool hasAov, const std::string& samplesName,
                       const std::string& aovName);

// The name of a Choice setting's value ("blinn-phong" for setting("shading") and SHADING_BLINN_PHONG);
// "unknown" for a value it does not list.
std::string choiceName(const Setting& setting, uint32_t value);
// The value of a Choice setting's name, or a one-line error listing the names.
Result<uint32_t> choiceValue(const Setting& setting, const std::string& name, const std::string& label);
// The names of a Choice setting, in order.
std::vector<std::string> choiceNames(const Setting& setting);

// The reference as Markdown: one table per group with each setting's command-line option, manifest
// key, values and default, and help. docs/settings.md holds exactly this text (a test checks it).
std::string settingsMarkdown();
// The schema as JSON, for other front ends (`raster settings --json`).
nlohmann::json schemaJson();

}  // namespace sr

#endif  // RASTER_SETTINGS_SCHEMA_H
