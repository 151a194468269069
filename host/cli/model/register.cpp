// The model command family, and the DOF and number lists its options take.
#include <cmath>

#include "commands.hpp"
#include "vibid/common/option_text.hpp"
#include "model/model_commands.hpp"
#include "vibid/common/error.hpp"

namespace vibid::cli {

void RegisterModelCommands(CLI::App& app) {
  RegisterModalCommand(app);
  RegisterFrfCommand(app);
  RegisterSimulateCommand(app);
}

std::vector<double> ParseNumberList(const std::string& text, const std::string& option) {
  std::vector<double> out;
  for (const std::string& item : SplitOptionList(text)) {
    double value = 0.0;
    Require(ParseNumber(item, value) == NumberText::kOk,
            option + ": '" + item + "' is not a finite number");
    out.push_back(value);
  }
  return out;
}

std::vector<int> ParseDofList(const std::string& text, const std::string& option) {
  std::vector<int> out;
  for (const double value : ParseNumberList(text, option)) {
    Require(
        value >= 1.0 && value == std::floor(value) && value < 1e6,
        option + ": DOF " + std::to_string(value) + " must be an integer >= 1 (DOFs count from 1)");
    out.push_back(static_cast<int>(value) - 1);
  }
  return out;
}

}  // namespace vibid::cli
