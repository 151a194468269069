// The model command family: modal, frf, simulate.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace vibid::cli {

void RegisterModalCommand(CLI::App& app);
void RegisterFrfCommand(CLI::App& app);
void RegisterSimulateCommand(CLI::App& app);

/// "1,3" → {0, 2} (DOFs counted from 1 on the command line); InputError naming `option`.
std::vector<int> ParseDofList(const std::string& text, const std::string& option);

/// "0.2,0.1" → the numbers; InputError naming `option`.
std::vector<double> ParseNumberList(const std::string& text, const std::string& option);

}  // namespace vibid::cli
