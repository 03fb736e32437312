// commands.cpp - the table of `raster`'s subcommands.
#include "cli/commands.h"

#include <cstdlib>

#include <fmt/format.h>

namespace sr {

const std::vector<CommandInfo>& commands()
{
    static const std::vector<CommandInfo> table = {
        {"render", "raster render [SCENE] [-o out.png|.npy] [--aov out.exr] [--stats out.json] [SETTINGS]",
         "render a scene (built-in when SCENE is omitted); --frames N --orbit AZ0:AZ1 renders a turntable"},
        {"compare", "raster compare A B [-o diff.png] [--tolerance LSB]",
         "compare two PNG images or two EXR AOVs (idiff-style report)"},
        {"bench",
         "raster bench [--backends cuda,vulkan,vulkan-graphics] [--scenes ...] [--warmup-ms MS] [--json F]",
         "the benchmark suite on several backends in one run; --warmup-ms MS draws untimed frames of each "
         "run for MS ms after its first, so that the GPU's clock is up when timing starts"},
        {"study", "raster study [--backends vulkan,cuda] [--json F]",
         "speed against accuracy per setting and failures per stress axis (ci/study-chart draws them)"},
        {"batch", "raster batch MANIFEST [--devices all|0,1] [--shard i/N] [SETTINGS]",
         "render every job of a JSON Lines manifest (a shard of it with --shard or a Slurm array), on one or "
         "more devices, skipping jobs already done"},
        {"view", "raster view [SCENE] [--backend auto|cuda|vulkan] [--script FILE]",
         "an interactive window (see docs/viewer.md for the controls)"},
        {"settings", "raster settings [--format markdown|json]",
         "every render setting: option, manifest key, values, default and help (the schema)"},
        {"commands", "raster commands", "this table of subcommands, as Markdown"},
    };
    return table;
}

const CommandInfo& command(const std::string& name)
{
    for (const CommandInfo& c : commands())
        if (c.name == name) return c;
    std::abort();  // a front end naming a subcommand the table lacks: a bug of this file
}

std::string commandsMarkdown()
{
    // A '|' inside a cell (a choice of values) would end the cell: Markdown tables take it escaped.
    auto cell = [](std::string text) {
        for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2))
            text.replace(at, 1, "\\|");
        return text;
    };
    std::string text = "| command | usual form | what it does |\n|---|---|---|\n";
    for (const CommandInfo& c : commands())
        text += fmt::format("| `{}` | `{}` | {} |\n", c.name, cell(c.synopsis), cell(c.summary));
    return text;
}

}  // namespace sr
