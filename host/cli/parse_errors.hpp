// CLI11's refusals of a command line in vibid's words: what is wrong, named as the user typed it,
// and the way out ('vibid COMMAND --help'), never CLI11's own sentences ("At Most 1 required but
// received 2", "The following argument was not expected").
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace vibid::cli {

/// The message for `error`, which CLI11 raised while `root` parsed a command line (the command
/// it had reached names the help to read). Empty for the successes CLI11 reports as errors
/// (--help, --version), whose own output stands.
std::string ParseErrorMessage(const CLI::ParseError& error, const CLI::App& root);

}  // namespace vibid::cli
