// usage_errors.cpp - see usage_errors.h.
#include "cli/usage_errors.h"

#include <algorithm>
#include <cctype>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "base/result.h"

namespace sr {

size_t editDistance(const std::string& a, const std::string& b)
{
    // d[i][j]: distance between the first i characters of a and the first j of b.
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1, 0));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        for (size_t j = 1; j <= b.size(); ++j) {
            size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    }
    return d[a.size()][b.size()];
}

std::string nearestName(const std::string& word, const std::vector<std::string>& candidates)
{
    // A third of the word's length: "rendr" and "mssa" are one edit away, while a short unrelated
    // word is not "corrected" into any name of similar length.
    const size_t limit = std::max<size_t>(1, word.size() / 3);
    std::string best;
    size_t bestDistance = limit + 1;
    for (const std::string& c : candidates) {
        size_t d = editDistance(word, c);
        if (d < bestDistance) {
            best = c;
            bestDistance = d;
        }
    }
    if (!best.empty()) return best;
    std::string prefixed;
    for (const std::string& c : candidates) {
        if (!word.empty() && c.compare(0, word.size(), word) == 0) {
            if (!prefixed.empty()) return "";
            prefixed = c;
        }
    }
    return prefixed;
}

namespace {

// An argument that names an option rather than giving a value: "-x" or "--name[=value]", but not a
// negative number ("--orbit -45:315") or "-" alone.
bool isOptionLike(const std::string& arg)
{
    if (arg.size() < 2 || arg[0] != '-') return false;
    char c = arg[1];
    return !(std::isdigit(static_cast<unsigned char>(c)) || c == '.');
}

// The long names of the command's options, without their "--".
std::vector<std::string> longOptionNames(const CLI::App& app)
{
    std::vector<std::string> names;
    for (const CLI::Option* option : app.get_options())
        for (const std::string& name : option->get_lnames()) names.push_back(name);
    return names;
}

std::string didYouMean(const std::string& nearest)
{
    return nearest.empty() ? "" : fmt::format("; did you mean '{}'?", nearest);
}

}  // namespace

std::string parseErrorMessage(const CLI::App& app, const std::vector<std::string>& args,
                              const CLI::ParseError& error)
{
    std::vector<std::string> commands;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        commands.push_back(sub->get_name());

    // The command is the first argument that is not an option (the top level takes none but --help).
    auto command =
        std::find_if(args.begin(), args.end(), [](const std::string& a) { return !isOptionLike(a); });
    if (command == args.end()) {
        if (args.empty()) return fmt::format("a command is required: {}", fmt::join(commands, ", "));
        return error.what();
    }
    if (std::find(commands.begin(), commands.end(), *command) == commands.end()) {
        std::string nearest = nearestName(*command, commands);
        if (!nearest.empty())
            return fmt::format("unknown command {}{}", quotedInput(*command), didYouMean(nearest));
        return fmt::format("unknown command {} (commands: {})", quotedInput(*command),
                           fmt::join(commands, ", "));
    }

    // An option the command does not have: CLI11 lists it among the unexpected arguments. Find the first
    // such option after the command (up to a "--", after which everything is positional).
    // (By type: CLI11 names a subcommand's ExtrasError after the subcommand, not "ExtrasError".)
    if (dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr) {
        const CLI::App* sub = app.get_subcommand(*command);
        for (auto it = command + 1; it != args.end() && *it != "--"; ++it) {
            if (!isOptionLike(*it)) continue;
            std::string name = it->substr(0, it->find('='));
            if (sub->get_option_no_throw(name) != nullptr) continue;
            std::string nearest;
            if (name.rfind("--", 0) == 0) nearest = nearestName(name.substr(2), longOptionNames(*sub));
            if (!nearest.empty()) nearest = "--" + nearest;
            return fmt::format(
                "unknown option {} for 'raster {}'{}{}", quotedInput(name), *command, didYouMean(nearest),
                nearest.empty() ? fmt::format(" (raster {} --help lists them)", *command) : "");
        }
    }
    return error.what();
}

}  // namespace sr
