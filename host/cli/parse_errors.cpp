#include "parse_errors.hpp"

#include <regex>
#include <vector>

namespace vibid::cli {
namespace {

/// The deepest command the parse reached: its help is the one to read.
const CLI::App* ReachedCommand(const CLI::App& root) {
  const CLI::App* app = &root;
  for (;;) {
    const std::vector<const CLI::App*> parsed =
        app->get_subcommands([](const CLI::App* c) { return c->parsed(); });
    if (parsed.empty()) return app;
    app = parsed.back();
  }
}

std::string CommandPath(const CLI::App* app) {
  std::string path;
  for (const CLI::App* a = app; a != nullptr; a = a->get_parent())
    path = a->get_name() + (path.empty() ? "" : " " + path);
  return path;
}

std::string CommandNames(const CLI::App* app) {
  std::string names;
  for (const CLI::App* c : app->get_subcommands([](const CLI::App*) { return true; }))
    names += (names.empty() ? "" : ", ") + c->get_name();
  return names;
}

std::string Values(const std::string& count) {
  return count + (count == "1" ? " value" : " values");
}

}  // namespace

std::string ParseErrorMessage(const CLI::ParseError& error, const CLI::App& root) {
  if (dynamic_cast<const CLI::Success*>(&error) != nullptr) return {};
  const CLI::App* command = ReachedCommand(root);
  const std::string path = CommandPath(command);
  const std::string help = "; '" + path + " --help' shows its form";
  const std::string what = error.what();
  std::smatch m;
  const auto match = [&](const char* pattern) {
    return std::regex_match(what, m, std::regex(pattern));
  };

  if (dynamic_cast<const CLI::ArgumentMismatch*>(&error) != nullptr) {
    if (match(R"((\S+): At Most 1 required but received (\d+))"))
      return m[1].str() + " was given " + m[2].str() + " times; give it once" + help;
    if (match(R"((\S+): At Most (\d+) required but received (\d+))"))
      return m[1].str() + " takes at most " + Values(m[2]) + ", got " + m[3].str() + help;
    if (match(R"((\S+): At least (\d+) required but received (\d+))"))
      return m[1].str() + " takes at least " + Values(m[2]) + ", got " + m[3].str() + help;
    if (match(R"(Expected exactly (\d+) arguments to (\S+), got (\d+))"))
      return m[2].str() + " takes " + Values(m[1]) + ", got " + m[3].str() + help;
    if (match(R"(Expected at least (\d+) arguments to (\S+), got (\d+))"))
      return m[2].str() + " takes at least " + Values(m[1]) + ", got " + m[3].str() + help;
    if (match(R"((\S+): \d+ required (\S+) missing)"))
      return m[1].str() + " needs a value (" + m[2].str() + ")" + help;
    if (match(R"((\S+) was given a disallowed flag override)"))
      return m[1].str() + " is a switch and takes no value" + help;
  }
  if (dynamic_cast<const CLI::RequiredError*>(&error) != nullptr) {
    if (match(R"(A subcommand( is required)?|Requires at least \d+ subcommands)"))
      return "'" + path + "' needs a command (" + CommandNames(command) + "); '" + path +
             " --help' says what each does";
    if (match(R"((.+) is required)")) return "'" + path + "' needs " + m[1].str() + help;
    if (match(R"(Exactly 1 option from \[(.+)\].*)"))
      return "'" + path + "' needs exactly one of " + m[1].str() + help;
    if (match(R"(At least 1 option from \[(.+)\])"))
      return "'" + path + "' needs one of " + m[1].str() + help;
  }
  if (dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr &&
      match(R"(The following arguments? (?:was|were) not expected: (.+))")) {
    return "'" + path + "' does not take " + m[1].str() + help;
  }
  if (dynamic_cast<const CLI::ExcludesError*>(&error) != nullptr &&
      match(R"((\S+) excludes (\S+))")) {
    return m[1].str() + " and " + m[2].str() + " cannot be given together; give one of them" + help;
  }
  if (dynamic_cast<const CLI::RequiresError*>(&error) != nullptr &&
      match(R"((\S+) requires (\S+))")) {
    return m[1].str() + " needs " + m[2].str() + " as well" + help;
  }
  if (dynamic_cast<const CLI::ValidationError*>(&error) != nullptr) {
    // CLI11's own validators (IsMember, Range, number conversion); vibid's own say it already.
    if (match(R"((\S+): (\S+) not in \{(.*)\})"))
      return m[1].str() + " '" + m[2].str() + "': expected one of " + m[3].str();
    if (match(R"((\S+): Value (\S+) not in range (\S+) to (\S+))"))
      return m[1].str() + " " + m[2].str() + ": must be in " + m[3].str() + ".." + m[4].str();
    if (match(R"((\S+): Value (.+) could not be converted.*)"))
      return m[1].str() + " '" + m[2].str() + "': not a value it takes" + help;
    return what;
  }
  if (dynamic_cast<const CLI::ConversionError*>(&error) != nullptr) {
    if (match(R"(Could not convert: (\S+) = (.*))"))
      return m[1].str() + " '" + m[2].str() + "': not a value it takes" + help;
    if (match(R"(The value (.*) is not an allowed value for (\S+))"))
      return m[2].str() + " '" + m[1].str() + "': not a value it takes" + help;
    if (match(R"((\S+): Should be true/false or a number)"))
      return m[1].str() + ": expected true or false" + help;
    if (match(R"((\S+): too many inputs for a flag)"))
      return m[1].str() + " is a switch and takes no value" + help;
  }
  // A refusal not foreseen above: what CLI11 saw, and where to read the command's form.
  return "the command line is not one '" + path + "' takes (" + what + ")" + help;
}

}  // namespace vibid::cli
