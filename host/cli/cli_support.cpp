#include "cli_support.hpp"

#include "vibid/common/json_keys.hpp"

#include <iostream>

#include "vibid/common/option_text.hpp"
#include "vibid/common/atomic_file.hpp"

namespace vibid::cli {

void EmitOutput(const std::string& content, const std::string& path) {
  if (path.empty() || path == "-") {
    std::cout << content;
    std::cout.flush();
  } else {
    WriteFileAtomic(path, content);
  }
}

void SayCautions(const std::vector<std::string>& cautions, const std::string& what) {
  if (cautions.empty()) return;
  std::cerr << "vibid: caution: " << what << " written with " << cautions.size()
            << " caution(s) (the CAUTION lines): read them before using it\n";
}

ClaimedOutput::ClaimedOutput(const std::string& path) {
  if (!path.empty() && path != "-") file_ = std::make_unique<AtomicOutputFile>(path);
}

void ClaimedOutput::Write(std::string_view content) {
  if (file_) {
    file_->Commit(content);
  } else {
    std::cout << content;
    std::cout.flush();
  }
}

std::string ClaimedOutput::Name() const { return file_ ? file_->path() : "stdout"; }

namespace {

/// An option of `app` or of a command above it (a device command takes the top level's
/// --device after its own name).
const CLI::Option* FindOption(const CLI::App* app, const std::string& name) {
  for (const CLI::App* a = app; a != nullptr; a = a->get_parent()) {
    if (const CLI::Option* o = a->get_option_no_throw(name)) return o;
  }
  return nullptr;
}

std::string CommandPath(const CLI::App* app) {
  std::string path;
  for (const CLI::App* a = app; a != nullptr; a = a->get_parent())
    path = a->get_name() + (path.empty() ? "" : " " + path);
  return path;
}

}  // namespace

std::string UnknownWordMessage(const CLI::App& root, const std::vector<std::string>& args) {
  const CLI::App* app = &root;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (word == "--") break;
    if (word.size() > 1 && word[0] == '-') {
      const std::string name = word.substr(0, word.find('='));
      const CLI::Option* o = FindOption(app, name);
      if (o == nullptr) {
        // Only long names are suggested: a short one is too short to be near anything.
        if (name.rfind("--", 0) != 0) continue;
        std::vector<std::string> known;
        for (const CLI::App* a = app; a != nullptr; a = a->get_parent()) {
          for (const CLI::Option* opt : a->get_options())
            for (const std::string& l : opt->get_lnames()) known.push_back("--" + l);
        }
        const std::string near = NearestName(name, known);
        const std::string path = CommandPath(app);
        return "unknown option '" + name + "' for '" + path + "'" +
               (near.empty() ? "; '" + path + " --help' lists its options"
                             : " (did you mean '" + near + "'?)");
      }
      // Its value is the next word (unless given as --name=value): not a command.
      if (word.find('=') == std::string::npos && o->get_items_expected_min() > 0) ++i;
      continue;
    }
    const std::vector<const CLI::App*> commands =
        app->get_subcommands([](const CLI::App*) { return true; });
    const CLI::App* next = nullptr;
    for (const CLI::App* c : commands) {
      if (c->check_name(word)) next = c;
    }
    if (next != nullptr) {
      app = next;
      continue;
    }
    // A word where a command is required is a command name, misspelt or not one.
    if (!commands.empty() && app->get_require_subcommand_min() > 0) {
      std::vector<std::string> names;
      for (const CLI::App* c : commands) names.push_back(c->get_name());
      const std::string near = NearestName(word, names);
      const std::string path = CommandPath(app);
      return "unknown command '" + word + "' for '" + path + "'" +
             (near.empty() ? "; '" + path + " --help' lists the commands"
                           : " (did you mean '" + near + "'?)");
    }
  }
  return {};
}

namespace {

CLI::Validator NumberValidator(bool allow_zero) {
  return CLI::Validator(
      [allow_zero](std::string& s) -> std::string {
        double v = 0.0;
        switch (ParseNumber(s, v)) {
          case NumberText::kNotANumber: return "'" + s + "' is not a number";
          case NumberText::kNotFinite: return "'" + s + "' is not a finite number";
          case NumberText::kOk: break;
        }
        if (allow_zero ? v < 0.0 : v <= 0.0)
          return "'" + s + (allow_zero ? "' must be >= 0" : "' must be > 0");
        return {};
      },
      allow_zero ? "NUMBER>=0" : "NUMBER>0");
}

}  // namespace

const CLI::Validator& PositiveNumber() {
  static const CLI::Validator v = NumberValidator(false);
  return v;
}

const CLI::Validator& NonNegativeNumber() {
  static const CLI::Validator v = NumberValidator(true);
  return v;
}

}  // namespace vibid::cli
