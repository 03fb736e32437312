// usage_errors.h - CLI11's parse errors as the one-line messages `raster` prints, naming the nearest
// valid command or option for a misspelt one.
//
// CLI11 2.1 reports a misspelt subcommand ("raster rendr") as "A subcommand is required" and a misspelt
// option ("--mssa 4") as "The following arguments were not expected", naming nothing a user could type
// instead. main() hands every parse error here and prints what comes back.
#ifndef RASTER_CLI_USAGE_ERRORS_H
#define RASTER_CLI_USAGE_ERRORS_H

#include <string>
#include <vector>

namespace CLI {
class App;
class ParseError;
}  // namespace CLI

namespace sr {

// Edit distance between a and b counting insertions, deletions, substitutions and swaps of two adjacent
// characters as one edit each (the optimal string alignment distance), so "comapre" is one edit from
// "compare".
size_t editDistance(const std::string& a, const std::string& b);

// The candidate that `word` most likely misspells: the nearest within max(1, length / 3) edits (the
// first of equals in `candidates` order), else the only candidate that starts with `word`; empty when
// there is none.
std::string nearestName(const std::string& word, const std::vector<std::string>& candidates);

// The one-line message for a parse error of `app` on the command line `args` (argv without the program
// name): an unknown command or option named with the nearest valid one ("unknown command 'rendr'; did
// you mean 'render'?", "unknown option '--mssa' for 'raster render'; did you mean '--msaa'?"), else
// CLI11's own message.
std::string parseErrorMessage(const CLI::App& app, const std::vector<std::string>& args,
                              const CLI::ParseError& error);

}  // namespace sr

#endif  // RASTER_CLI_USAGE_ERRORS_H
