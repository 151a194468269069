// The one way a command joins the command line: its options bind into an Args value that CLI11
// fills while parsing, and its Run gets that value once the whole line has parsed (so options given
// before the subcommand, like --device, are in place).
#pragma once

#include <memory>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

namespace vibid::cli {

/// Adds subcommand `name` to `parent` with a fresh Args; the returned pointers stay valid for the
/// life of the app (CLI11 owns the subcommand, the callback owns the Args).
template <typename Args>
std::pair<CLI::App*, Args*> AddCommand(CLI::App& parent, const std::string& name,
                                       const std::string& description, void (*run)(const Args&)) {
  auto args = std::make_shared<Args>();
  CLI::App* cmd = parent.add_subcommand(name, description);
  cmd->callback([args, run] { run(*args); });
  return {cmd, args.get()};
}

}  // namespace vibid::cli
