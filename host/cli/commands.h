// commands.h - the subcommands of `raster`, declared once: the command line's help takes each one's
// summary from here, and `raster commands` prints the table the README shows (a test checks that it does).
#ifndef RASTER_CLI_COMMANDS_H
#define RASTER_CLI_COMMANDS_H

#include <string>
#include <vector>

namespace sr {

struct CommandInfo {
    std::string name;      // raster NAME
    std::string synopsis;  // its usual form, options abridged
    std::string summary;   // one line: the subcommand's help in `raster --help`
};

// Every subcommand, in the order of `raster --help`.
const std::vector<CommandInfo>& commands();
// The subcommand named `name`; `name` must be in the table.
const CommandInfo& command(const std::string& name);

// The table as Markdown: command, usual form and what it does, one row each.
std::string commandsMarkdown();

}  // namespace sr

#endif  // RASTER_CLI_COMMANDS_H
