// options.cpp - see options.h.
#include "cli/options.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace sr {

std::string optionHelp(const Setting& s)
{
    std::string values;
    if (s.type == SettingType::Choice) {
        for (const std::string& name : choiceNames(s)) values += (values.empty() ? "" : ", ") + name;
    } else if (s.type == SettingType::Uint && !s.numbers.empty()) {
        for (uint32_t n : s.numbers) values += fmt::format("{}{}", values.empty() ? "" : ", ", n);
    } else if (s.type == SettingType::Uint || s.type == SettingType::Float) {
        values = fmt::format("{}{}..{}", s.allowAuto ? "auto, " : "", s.min, s.max);
    }
    std::string help = s.help;
    if (!values.empty()) help += " [" + values + "]";
    if (s.type != SettingType::Bool) {
        help += " (default " + settingDefaultText(s);
        if (!s.defaultNote.empty()) help += ": " + s.defaultNote;
        help += ")";
    }
    return help;
}

void addSettingOptions(CLI::App& app, std::function<void(const Setting&, const nlohmann::json&)> store)
{
    for (const Setting& s : settingsSchema()) {
        const std::string flag = "--" + s.name;
        if (s.type == SettingType::Bool) {
            app.add_flag_function(
                flag, [&s, store](int64_t) { store(s, nlohmann::json(true)); }, optionHelp(s));
            continue;
        }
        app.add_option_function<std::string>(
               flag,
               [&s, store, flag](const std::string& text) {
                   auto value = parseSettingText(s, text, flag);
                   if (!value) throw CLI::ValidationError(value.error().message);
                   store(s, *value);
               },
               optionHelp(s))
            ->type_name(s.type == SettingType::Choice ? "NAME"
                        : s.type == SettingType::Vec3 ? "X,Y,Z"
                                                      : "VALUE");
    }
}

void addSettingOptions(CLI::App& app, RenderOptions& options)
{
    addSettingOptions(app,
                      [&options](const Setting& s, const nlohmann::json& value) { s.set(options, value); });
}

}  // namespace sr
